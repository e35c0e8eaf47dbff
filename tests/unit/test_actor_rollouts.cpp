// The actor over memq:// (one in-process LCM shared with a fake learner): parameters in, rollout
// chunks and heartbeats out.
#include <gtest/gtest.h>

#include <limits>

#include <thread>

#include <chrono>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "actors/actor.hpp"
#include "actors/gaussian_behaviour.hpp"
#include "common/config/run_config.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "common/transport/channels.hpp"
#include "learner/intake/rollout_assembler.hpp"
#include "common/transport/transport.hpp"
#include "masa/lcmt_actor_heartbeat.hpp"
#include "masa/lcmt_policy_params.hpp"
#include "masa/lcmt_rollout_chunk.hpp"

namespace masa {
namespace {

constexpr int64_t kRolloutRunId = 777;

// A PPO run's actor acts with the policy half of the learner's model.
model::InferencePolicy<float>& gaussianPolicy(actor::Actor& a) {
  return dynamic_cast<actor::GaussianBehaviour&>(a.behaviour()).policy();
}
constexpr int kHorizon = 8;
constexpr int kEpisodeSteps = 5;  // shorter than the horizon: every env finishes an episode

config::RunConfig smallRolloutConfig(uint64_t seed, const std::string& task = "trifinger_lift") {
  return config::loadRunConfig(std::string(MASA_SOURCE_DIR) + "/configs",
                               {"task=" + task, "seed=" + std::to_string(seed), "ppo.horizon=" + std::to_string(kHorizon),
                                "model.policy_hidden=[16]", "model.critic_hidden=[16]",
                                "env.max_episode_steps=" + std::to_string(kEpisodeSteps)});
}

// Plays the learner's side: its own initialized model, broadcast as the policy prefix.
struct FakeLearner {
  FakeLearner(const config::RunConfig& rc, uint64_t init_seed)
      : spec(sym::SymmetrySpec::load(rc.spec_path)), model(spec, rc.model), rc(rc) {
    Rng rng(init_seed);
    model.initialize(rng);
  }
  masa::lcmt_policy_params message(int64_t version, float param_shift = 0.0f) const {
    masa::lcmt_policy_params p;
    p.run_id = kRolloutRunId;
    p.utime = 0;
    p.version = version;
    p.method = model::methodName(rc.method);
    p.task = rc.task;
    int policy = model.params().size();
    for (const auto& s : model.params().segments())
      if (s.name.rfind("critic", 0) == 0) {
        policy = s.offset;
        break;
      }
    p.num_params = policy;
    p.params.assign(model.params().values().data(), model.params().values().data() + policy);
    for (auto& v : p.params) v += param_shift;
    p.obs_dim = spec.obsDim();
    p.obs_mean.assign(p.obs_dim, 0.1f);
    p.obs_std.assign(p.obs_dim, 2.0f);
    return p;
  }
  sym::SymmetrySpec spec;
  model::ActorCritic<float> model;
  config::RunConfig rc;
};

// The learner's chunk gate, configured for this test run's dimensions (warnings off).
learner::AssemblerConfig assemblerConfigFor(const FakeLearner& learner) {
  learner::AssemblerConfig ac;
  ac.run_id = kRolloutRunId;
  ac.horizon = kHorizon;
  ac.obs_dim = learner.spec.obsDim();
  ac.act_dim = learner.spec.actDim();
  ac.warn_interval_s = -1;
  return ac;
}

struct Capture {
  explicit Capture(transport::Transport& t) {
    t.subscribeRaw(transport::kRolloutChannel, [this](const void* d, int n) {
      chunks.emplace_back(static_cast<const uint8_t*>(d), static_cast<const uint8_t*>(d) + n);
    });
    t.subscribe<masa::lcmt_actor_heartbeat>(transport::kHeartbeatChannel,
                                            [this](const masa::lcmt_actor_heartbeat& h) { heartbeats.push_back(h); });
  }
  std::vector<std::vector<uint8_t>> chunks;
  std::vector<masa::lcmt_actor_heartbeat> heartbeats;
};

masa::lcmt_rollout_chunk decode(const std::vector<uint8_t>& bytes) {
  masa::lcmt_rollout_chunk c;
  EXPECT_EQ(c.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return c;
}

actor::ActorOptions rolloutOptions(int num_envs, int64_t max_rollouts) {
  actor::ActorOptions o;
  o.actor_id = 3;
  o.num_envs = num_envs;
  o.run_id = kRolloutRunId;
  o.max_rollouts = max_rollouts;
  o.threads = 2;
  o.chunk_bytes = 8000;  // small, so that a rollout is split into several chunks
  o.incarnation = 1;        // bit-identical chunks from run to run
  o.await_params_s = 0;     // no learner here to wait for
  return o;
}

TEST(ActorRollouts, ChunksFromLearnerParamsPassTheAssemblerWithAllEnvsAndEpisodes) {
  const auto rc = smallRolloutConfig(1);
  transport::Transport bus("memq://");
  Capture cap(bus);
  FakeLearner learner(rc, 5);
  const int E = 6;
  actor::Actor actor(rc, rolloutOptions(E, 2), &bus);
  ASSERT_TRUE(bus.publish(transport::kPolicyChannel, learner.message(1)));
  EXPECT_EQ(actor.run(), 2);
  bus.drain();
  ASSERT_EQ(actor.paramsRejected(), 0);

  learner::RolloutAssembler assembler(assemblerConfigFor(learner));
  assembler.setLearnerVersion(1);
  ASSERT_GE(cap.chunks.size(), 4u) << "expected each rollout split into at least two chunks";
  std::vector<std::set<int>> envs_seen(2);
  int episodes = 0, finals = 0;
  for (const auto& bytes : cap.chunks) {
    const auto v = assembler.acceptEncoded(bytes.data(), static_cast<int>(bytes.size()));
    ASSERT_TRUE(v) << "dropped: " << static_cast<int>(v.reason);
    const auto& m = v.chunk->msg();
    EXPECT_EQ(m.policy_version, 1);
    EXPECT_EQ(m.actor_id, 3);
    ASSERT_GE(m.rollout_seq, 0);
    ASSERT_LT(m.rollout_seq, 2);
    for (int e = 0; e < m.num_envs; ++e) EXPECT_TRUE(envs_seen[m.rollout_seq].insert(m.env_offset + e).second);
    for (float x : m.obs) ASSERT_TRUE(std::isfinite(x));
    for (float x : m.reward) ASSERT_TRUE(std::isfinite(x));
    episodes += m.num_episodes;
    finals += m.num_final;
    for (int k = 0; k < m.num_episodes; ++k) {
      EXPECT_EQ(m.episode_length[k], kEpisodeSteps);
      EXPECT_TRUE(std::isfinite(m.episode_return[k]));
    }
    EXPECT_EQ(m.num_terms, static_cast<int>(m.term_names.size()));
    EXPECT_GT(m.num_terms, 0);
  }
  EXPECT_EQ(assembler.stats().dropped(), 0);
  for (const auto& s : envs_seen) EXPECT_EQ(static_cast<int>(s.size()), E);
  // 2 rollouts of 8 steps with 5-step episodes: every env ends episodes at steps 5, 10 and 15
  // (episodes run on across rollouts), all by the time limit.
  EXPECT_EQ(episodes, 3 * E);
  EXPECT_EQ(finals, 3 * E) << "time-limit ends carry their pre-reset observation";
}

// The actor keeps how long each rollout took and how long it then waited for the parameters the
// next one needed: here no learner answers, so each wait runs to its budget (0.05 s, then doubled
// before any answer), and the last rollout is followed by none.
TEST(ActorRollouts, EachRolloutsCollectTimeAndTheWaitForParametersAfterItAreKept) {
  const auto rc = smallRolloutConfig(1);
  transport::Transport bus("memq://");
  FakeLearner learner(rc, 5);
  actor::ActorOptions opt = rolloutOptions(4, 3);
  opt.await_params_s = 0.05;
  actor::Actor actor(rc, opt, &bus);
  ASSERT_TRUE(bus.publish(transport::kPolicyChannel, learner.message(1)));
  EXPECT_EQ(actor.run(), 3);
  ASSERT_EQ(actor.collectSeconds().size(), 3u);
  for (double s : actor.collectSeconds()) EXPECT_GT(s, 0.0);
  ASSERT_EQ(actor.awaitSeconds().size(), 2u) << "a wait after each rollout but the last";
  EXPECT_GE(actor.awaitSeconds()[0], 0.045);
  EXPECT_GE(actor.awaitSeconds()[1], 0.09) << "a timed-out wait doubles the next before any answer";
  EXPECT_LT(actor.awaitSeconds()[1], 1.0);
}

TEST(ActorRollouts, ParametersPublishedMidRolloutApplyFromTheNextRollout) {
  const auto rc = smallRolloutConfig(2);
  transport::Transport bus("memq://");
  Capture cap(bus);
  FakeLearner learner(rc, 5);
  auto opt = rolloutOptions(3, 2);
  opt.after_step = [&](int64_t seq, int t) {
    if (seq == 0 && t == 3) bus.publish(transport::kPolicyChannel, learner.message(2, 0.05f));
  };
  actor::Actor actor(rc, opt, &bus);
  bus.publish(transport::kPolicyChannel, learner.message(1));
  ASSERT_TRUE(actor.pollParams(100));
  ASSERT_EQ(actor.policyVersion(), 1);
  ASSERT_TRUE(actor.collectAndPublish());
  EXPECT_EQ(actor.policyVersion(), 1) << "version 2 arrived mid-rollout but must wait";
  ASSERT_TRUE(actor.collectAndPublish());
  EXPECT_EQ(actor.policyVersion(), 2);
  bus.drain();
  ASSERT_FALSE(cap.chunks.empty());
  for (const auto& bytes : cap.chunks) {
    const auto m = decode(bytes);
    EXPECT_EQ(m.policy_version, m.rollout_seq == 0 ? 1 : 2) << "rollout " << m.rollout_seq;
  }
  // The swapped-in parameters and normalizer are the broadcast ones.
  const auto msg = learner.message(2, 0.05f);
  for (int i = 0; i < msg.num_params; ++i) ASSERT_EQ(gaussianPolicy(actor).params().values()[i], msg.params[i]);
  EXPECT_NEAR(gaussianPolicy(actor).obsNormalizer().mean()[0], 0.1, 1e-6);
}

std::vector<std::vector<uint8_t>> runOnce(uint64_t seed, int threads) {
  const auto rc = smallRolloutConfig(seed);
  transport::Transport bus("memq://");
  Capture cap(bus);
  FakeLearner learner(rc, 5);
  auto opt = rolloutOptions(4, 2);
  opt.threads = threads;
  actor::Actor actor(rc, opt, &bus);
  bus.publish(transport::kPolicyChannel, learner.message(1));
  actor.run();
  bus.drain();
  return cap.chunks;
}

TEST(ActorRollouts, SameSeedGivesBitIdenticalChunksForAnyThreadCount) {
  const auto a = runOnce(11, 1);
  const auto b = runOnce(11, 1);
  const auto c = runOnce(11, 3);
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, c) << "per-env generators make the result independent of the thread count";
}

TEST(ActorRollouts, DifferentSeedGivesDifferentChunks) {
  const auto a = runOnce(11, 2);
  const auto b = runOnce(12, 2);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_NE(decode(a[0]).actions, decode(b[0]).actions);
}

TEST(ActorRollouts, HeartbeatNamesTheActorAndItsVersion) {
  const auto rc = smallRolloutConfig(3, "a1_beam");
  transport::Transport bus("memq://");
  Capture cap(bus);
  FakeLearner learner(rc, 5);
  actor::Actor actor(rc, rolloutOptions(2, 1), &bus);
  bus.publish(transport::kPolicyChannel, learner.message(4));
  actor.run();
  bus.drain();
  ASSERT_GE(cap.heartbeats.size(), 2u) << "one at start, one at stop";
  EXPECT_EQ(cap.heartbeats.front().policy_version, -1) << "no parameters yet at start";
  const auto& last = cap.heartbeats.back();
  EXPECT_EQ(last.run_id, kRolloutRunId);
  EXPECT_EQ(last.actor_id, 3);
  EXPECT_EQ(last.num_envs, 2);
  EXPECT_EQ(last.policy_version, 4);
  EXPECT_EQ(last.rollouts_sent, 1);
  EXPECT_GT(last.steps_per_second, 0.0f);
}

// On a lossy LAN the learner repeats its parameters until every actor acknowledges them (issue
// #33): an actor sends a heartbeat naming the newest version it holds as soon as parameters reach
// it, between the steps of a rollout too (it acts with them from the next rollout), and again for a
// repeat (its acknowledgement may have been lost); a rejected message is not acknowledged.
TEST(ActorRollouts, ParametersAreAcknowledgedAtOnceInAHeartbeatAndARejectedMessageIsNot) {
  const auto rc = smallRolloutConfig(3, "a1_beam");
  transport::Transport bus("memq://");
  Capture cap(bus);
  FakeLearner learner(rc, 5);
  auto o = rolloutOptions(2, -1);
  o.heartbeat_interval_s = 3600;  // no heartbeat but the acknowledgements
  o.after_step = [&](int64_t rollout, int t) {
    if (rollout == 0 && t == 1) bus.publish(transport::kPolicyChannel, learner.message(5));
  };
  actor::Actor actor(rc, o, &bus);
  actor.publishHeartbeat();
  bus.drain();
  cap.heartbeats.clear();

  bus.publish(transport::kPolicyChannel, learner.message(4));
  ASSERT_TRUE(actor.pollParams(10));
  bus.drain();
  ASSERT_EQ(cap.heartbeats.size(), 1u) << "parameters came and no heartbeat said so";
  EXPECT_EQ(cap.heartbeats[0].params_version, 4);
  EXPECT_EQ(cap.heartbeats[0].policy_version, 4);

  bus.publish(transport::kPolicyChannel, learner.message(4));  // the learner's repeat
  actor.pollParams(0);
  bus.drain();
  ASSERT_EQ(cap.heartbeats.size(), 2u) << "a repeat is acknowledged again";
  EXPECT_EQ(cap.heartbeats[1].params_version, 4);

  auto hostile = learner.message(5);
  hostile.task = "no_such_task";
  bus.publish(transport::kPolicyChannel, hostile);
  actor.pollParams(0);
  bus.drain();
  EXPECT_EQ(actor.paramsRejected(), 1);
  EXPECT_EQ(cap.heartbeats.size(), 2u) << "a rejected message was acknowledged";

  ASSERT_TRUE(actor.collectAndPublish());  // version 5 arrives at step 1
  bus.drain();
  ASSERT_EQ(cap.heartbeats.size(), 3u);
  EXPECT_EQ(cap.heartbeats[2].params_version, 5) << "acknowledged mid-rollout";
  EXPECT_EQ(cap.heartbeats[2].policy_version, 4) << "still acting with version 4 until the next rollout";
}

TEST(ActorRollouts, ParametersOfAnotherRunOrTaskAreIgnored) {
  const auto rc = smallRolloutConfig(4);
  transport::Transport bus("memq://");
  FakeLearner learner(rc, 5);
  actor::Actor actor(rc, rolloutOptions(1, 1), &bus);
  auto other_run = learner.message(1);
  other_run.run_id = kRolloutRunId + 1;
  bus.publish(transport::kPolicyChannel, other_run);
  auto other_task = learner.message(1);
  other_task.task = "a1_beam";
  bus.publish(transport::kPolicyChannel, other_task);
  EXPECT_FALSE(actor.pollParams(10));
  EXPECT_FALSE(actor.hasParams());
  EXPECT_EQ(actor.paramsRejected(), 1);
}

// One rejected message must not outlive itself: an actor that remembered the version of a message
// it rejected (2^51, with an unknown task) ignored every real update after it, for good.
TEST(ActorRollouts, ARejectedParameterMessageIsNotRememberedAndTheLearnersNextParametersAreTaken) {
  const auto rc = smallRolloutConfig(4);
  transport::Transport bus("memq://");
  FakeLearner learner(rc, 5);
  actor::Actor actor(rc, rolloutOptions(1, -1), &bus);
  auto hostile = learner.message(int64_t{1} << 51);
  hostile.task = "no_such_task";
  bus.publish(transport::kPolicyChannel, hostile);
  EXPECT_FALSE(actor.pollParams(10));
  EXPECT_EQ(actor.paramsRejected(), 1);
  bus.publish(transport::kPolicyChannel, learner.message(1));
  ASSERT_TRUE(actor.pollParams(10)) << "the learner's first parameters after a rejected message";
  EXPECT_EQ(actor.policyVersion(), 1);
  // Again while acting: the next real version is swapped in at the next rollout.
  bus.publish(transport::kPolicyChannel, hostile);
  bus.publish(transport::kPolicyChannel, learner.message(2));
  actor.pollParams(10);
  ASSERT_TRUE(actor.collectAndPublish());
  EXPECT_EQ(actor.policyVersion(), 2);
  EXPECT_EQ(actor.paramsRejected(), 2);
}

// Versions are only believed as plausible steps: a message a million versions ahead of the actor
// is rejected (and not remembered), so the learner's real next version is still taken.
TEST(ActorRollouts, AVersionFarAheadOfTheActorsIsRejectedAndTheRealNextVersionIsTaken) {
  const auto rc = smallRolloutConfig(4);
  transport::Transport bus("memq://");
  FakeLearner learner(rc, 5);
  actor::Actor actor(rc, rolloutOptions(1, -1), &bus);
  bus.publish(transport::kPolicyChannel, learner.message(1));
  ASSERT_TRUE(actor.pollParams(10));
  bus.publish(transport::kPolicyChannel, learner.message(1 + 2'000'000, 0.5f));
  actor.pollParams(10);
  ASSERT_TRUE(actor.collectAndPublish());
  EXPECT_EQ(actor.policyVersion(), 1) << "a version 2e6 ahead must not be taken";
  EXPECT_EQ(actor.paramsRejected(), 1);
  bus.publish(transport::kPolicyChannel, learner.message(2));
  actor.pollParams(10);
  ASSERT_TRUE(actor.collectAndPublish());
  EXPECT_EQ(actor.policyVersion(), 2);
  // A fresh actor (no parameters yet) measures from version 0.
  actor::Actor fresh(rc, rolloutOptions(1, -1), &bus);
  bus.publish(transport::kPolicyChannel, learner.message(int64_t{1} << 49));
  EXPECT_FALSE(fresh.pollParams(10));
  bus.publish(transport::kPolicyChannel, learner.message(3));
  EXPECT_TRUE(fresh.pollParams(10));
  EXPECT_EQ(fresh.policyVersion(), 3);
}

// Without authentication, a corrupted or forged message with a valid body and a plausible version
// ahead of the learner's was taken, and the actor then ignored the learner's own parameters (all
// "older") for good while the learner dropped its chunks as future_version: a live fuzz run
// stalled this way. The learner's repeats below the actor's version now take it back.
TEST(ActorRollouts, AVersionTheLearnerNeverPublishedIsGivenUpWhenTheLearnerKeepsPublishingItsOwn) {
  const auto rc = smallRolloutConfig(4);
  transport::Transport bus("memq://");
  FakeLearner learner(rc, 5);
  actor::Actor actor(rc, rolloutOptions(1, -1), &bus);
  bus.publish(transport::kPolicyChannel, learner.message(7));
  ASSERT_TRUE(actor.pollParams(10));
  bus.publish(transport::kPolicyChannel, learner.message(985, 0.25f));  // a bit flip in the version
  actor.pollParams(10);
  ASSERT_TRUE(actor.collectAndPublish());
  ASSERT_EQ(actor.policyVersion(), 985);
  // One or two late copies of older parameters are still ignored ...
  bus.publish(transport::kPolicyChannel, learner.message(7));
  bus.publish(transport::kPolicyChannel, learner.message(7));
  actor.pollParams(10);
  ASSERT_TRUE(actor.collectAndPublish());
  EXPECT_EQ(actor.policyVersion(), 985);
  // ... the third in a row, with none at the actor's version, is the learner's: taken back.
  bus.publish(transport::kPolicyChannel, learner.message(7));
  actor.pollParams(10);
  ASSERT_TRUE(actor.collectAndPublish());
  EXPECT_EQ(actor.policyVersion(), 7);
  EXPECT_EQ(gaussianPolicy(actor).params().values().head(3), learner.model.params().values().head(3));
  // A repeat at the actor's version in between resets the count.
  bus.publish(transport::kPolicyChannel, learner.message(985, 0.25f));
  actor.pollParams(10);
  ASSERT_TRUE(actor.collectAndPublish());
  ASSERT_EQ(actor.policyVersion(), 985);
  for (int version : {7, 7, 985, 7, 7}) bus.publish(transport::kPolicyChannel, learner.message(version, version == 985 ? 0.25f : 0.0f));
  actor.pollParams(10);
  ASSERT_TRUE(actor.collectAndPublish());
  EXPECT_EQ(actor.policyVersion(), 985);
}

TEST(ActorRollouts, WholeModelParametersAreAcceptedAsWellAsThePolicyPrefix) {
  const auto rc = smallRolloutConfig(4);
  transport::Transport bus("memq://");
  FakeLearner learner(rc, 5);
  actor::Actor actor(rc, rolloutOptions(1, 1), &bus);
  auto whole = learner.message(1);
  whole.num_params = learner.model.params().size();
  whole.params.assign(learner.model.params().values().data(),
                      learner.model.params().values().data() + whole.num_params);
  bus.publish(transport::kPolicyChannel, whole);
  ASSERT_TRUE(actor.pollParams(10));
  // The critic part is not the actor's: it keeps the policy prefix.
  EXPECT_EQ(gaussianPolicy(actor).params().values(), learner.model.params().values().head(learner.model.policyParamCount()));
}

TEST(ActorRollouts, StartWithoutLearnerActsWithVersionZero) {
  const auto rc = smallRolloutConfig(5);
  transport::Transport bus("memq://");
  Capture cap(bus);
  auto opt = rolloutOptions(2, 1);
  opt.start_without_learner = true;
  actor::Actor actor(rc, opt, &bus);
  EXPECT_EQ(actor.run(), 1);
  bus.drain();
  ASSERT_FALSE(cap.chunks.empty());
  EXPECT_EQ(decode(cap.chunks[0]).policy_version, 0);
}

// Restart detection rests on the incarnation, not on the numbering: both processes number their
// rollouts 0, 1, and the second is neither taken for replays of the first nor for an outage.
TEST(ActorRollouts, ARestartedActorIsANewIncarnationNumberedFromZeroAndIsAccepted) {
  const auto rc = smallRolloutConfig(7);
  transport::Transport bus("memq://");
  Capture cap(bus);
  FakeLearner learner(rc, 5);
  auto opt = rolloutOptions(2, 2);
  opt.incarnation = actor::kIncarnationFromClock;  // what masa_actor does
  int64_t incarnation[2];
  for (int process = 0; process < 2; ++process) {  // the same actor id, twice: killed and restarted
    actor::Actor actor(rc, opt, &bus);
    incarnation[process] = actor.incarnation();
    bus.publish(transport::kPolicyChannel, learner.message(1));
    EXPECT_EQ(actor.run(), 2);
    bus.drain();
  }
  EXPECT_GT(incarnation[0], 0);
  EXPECT_NE(incarnation[1], incarnation[0]) << "processes started microseconds apart still differ";
  for (const auto& bytes : cap.chunks) EXPECT_LT(decode(bytes).rollout_seq, 2) << "numbered from 0 by each process";
  learner::RolloutAssembler assembler(assemblerConfigFor(learner));
  assembler.setLearnerVersion(1);
  for (const auto& bytes : cap.chunks) {
    const auto v = assembler.acceptEncoded(bytes.data(), static_cast<int>(bytes.size()));
    EXPECT_TRUE(v) << "dropped: " << learner::dropReasonName(v.reason);
  }
  EXPECT_EQ(assembler.actorTally(3).accepted, static_cast<int64_t>(cap.chunks.size()));
  EXPECT_EQ(assembler.actorTally(3).numberings, 2);
}

TEST(ActorRollouts, FaultInjectionThrowsAwayTheRequestedShareOfChunksReproducibly) {
  const auto rc = smallRolloutConfig(8, "a1_beam");
  auto run = [&](uint64_t drop_seed) {
    transport::Transport bus("memq://");
    Capture cap(bus);
    auto opt = rolloutOptions(6, 6);
    opt.chunk_bytes = 1;  // one environment per chunk: 36 chunks
    opt.start_without_learner = true;
    opt.drop_chunks_percent = 40;
    opt.drop_seed = drop_seed;
    actor::Actor actor(rc, opt, &bus);
    actor.run();
    bus.drain();
    EXPECT_EQ(actor.chunksPublished(), static_cast<int64_t>(cap.chunks.size()));
    std::vector<int64_t> kept;
    for (const auto& b : cap.chunks) {
      const auto m = decode(b);
      kept.push_back(m.rollout_seq * 1000 + m.chunk_index);
    }
    return std::make_pair(actor.chunksDropped(), kept);
  };
  const auto [dropped, kept] = run(3);
  const double total = static_cast<double>(dropped + static_cast<int64_t>(kept.size()));
  ASSERT_EQ(total, 36);
  EXPECT_NEAR(dropped / total, 0.4, 0.2);
  EXPECT_EQ(run(3).second, kept) << "the same seed throws away the same chunks";
  EXPECT_NE(run(4).second, kept);
}

TEST(ActorRollouts, StopFlagEndsTheRunBetweenSteps) {
  const auto rc = smallRolloutConfig(6);
  transport::Transport bus("memq://");
  Capture cap(bus);
  std::atomic<bool> stop{false};
  auto opt = rolloutOptions(2, -1);
  opt.start_without_learner = true;
  opt.stop = &stop;
  opt.after_step = [&](int64_t seq, int t) {
    if (seq == 1 && t == 2) stop = true;
  };
  actor::Actor actor(rc, opt, &bus);
  EXPECT_EQ(actor.run(), 1) << "the interrupted rollout is not sent";
}

// A fast actor waits (bounded) for the learner's next version instead of collecting rollouts the
// learner would drop as stale; with no learner the wait expires and collection goes on.
TEST(ActorRollouts, BetweenRolloutsTheActorWaitsBoundedForNewerParameters) {
  const auto rc = smallRolloutConfig(8);
  transport::Transport bus("memq://");
  auto opt = rolloutOptions(2, 3);
  opt.start_without_learner = true;
  opt.await_params_s = 0.4;
  actor::Actor actor(rc, opt, &bus);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(actor.run(), 3);
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(elapsed, 0.8) << "two waits of 0.4 s between three rollouts (none after the last)";
}

// With ppo.max_policy_lag 1 the actor collects its next rollout while the learner learns from the
// last (no wait after the first rollout), but not a third before the first is answered.
TEST(ActorRollouts, WithPolicyLagOneTheActorCollectsOneRolloutAheadAndWaitsBeforeTheNext) {
  auto rc = smallRolloutConfig(8);
  rc.rollout.max_policy_lag = 1;
  transport::Transport bus("memq://");
  auto opt = rolloutOptions(2, 3);
  opt.start_without_learner = true;
  opt.await_params_s = 1.0;
  actor::Actor actor(rc, opt, &bus);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(actor.run(), 3);
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(elapsed, 1.0) << "one wait, before the third rollout";
  EXPECT_LT(elapsed, 1.9) << "no wait after the first rollout (with lag 0: two waits, 2 s)";
}

TEST(ActorRollouts, NewerParametersEndTheWaitAtOnce) {
  const auto rc = smallRolloutConfig(9);
  transport::Transport bus("memq://");
  FakeLearner learner(rc, 5);
  auto opt = rolloutOptions(2, 2);
  opt.await_params_s = 30.0;  // a missed wake-up would show as a 30 s test
  // Each rollout's chunk is answered with the next version, as a learner does after its update.
  int64_t next = 1;
  bus.subscribeRaw(transport::kRolloutChannel,
                   [&](const void*, int) { bus.publish(transport::kPolicyChannel, learner.message(next++)); });
  actor::Actor actor(rc, opt, &bus);
  bus.publish(transport::kPolicyChannel, learner.message(0));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(actor.run(), 2);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 20.0);
  EXPECT_GE(actor.policyVersion(), 1);
}

// An actor whose learner is gone stops publishing and exits (issue #9: it used to simulate and
// publish forever). Here the learner sends its parameters once and is never heard again.
TEST(ActorRollouts, AnActorWhoseLearnerFallsSilentStopsPublishingAndExits) {
  const auto rc = smallRolloutConfig(10);
  transport::Transport bus("memq://");
  FakeLearner learner(rc, 5);
  auto opt = rolloutOptions(2, 20);
  opt.await_params_s = 0.05;
  opt.learner_silence_pause_s = 0.3;
  opt.learner_silence_exit_s = 0.8;
  int chunks = 0;
  bus.subscribeRaw(transport::kRolloutChannel, [&](const void*, int) { ++chunks; });
  actor::Actor actor(rc, opt, &bus);
  bus.publish(transport::kPolicyChannel, learner.message(0));
  const auto start = std::chrono::steady_clock::now();
  const int64_t rollouts = actor.run();
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(rollouts, 20) << "the actor went on publishing without its learner";
  EXPECT_GE(rollouts, 1);
  EXPECT_GE(elapsed, 0.8);
  EXPECT_LT(elapsed, 5.0);
  EXPECT_GT(chunks, 0);
}

// The learner's periodic repeat of the parameters the actor already holds keeps it publishing.
TEST(ActorRollouts, TheLearnersRepeatedParametersKeepTheActorGoing) {
  const auto rc = smallRolloutConfig(11);
  transport::Transport bus("memq://");
  FakeLearner learner(rc, 5);
  auto opt = rolloutOptions(2, 6);
  opt.await_params_s = 0.15;
  opt.await_params_max_s = 0.15;  // this fake repeats only when a rollout comes: waits that grow
                                  // (no answer ever comes) would starve it; a real learner repeats on its own
  opt.learner_silence_pause_s = 0.3;
  opt.learner_silence_exit_s = 0.6;
  // Every rollout is answered with a repeat of version 0, as a busy learner's republish would be.
  bus.subscribeRaw(transport::kRolloutChannel, [&](const void*, int) { bus.publish(transport::kPolicyChannel, learner.message(0)); });
  actor::Actor actor(rc, opt, &bus);
  bus.publish(transport::kPolicyChannel, learner.message(0));
  EXPECT_EQ(actor.run(), 6);
}

// docs/inputs.md gap 10: a message at the actor's own version was taken as the learner's repeat
// unchecked; a malformed one (a NaN parameter) now is refused, counted, and keeps nothing going.
TEST(ActorRollouts, AMalformedMessageAtTheActorsVersionIsRefusedAndDoesNotCountAsTheLearner) {
  const auto rc = smallRolloutConfig(12);
  transport::Transport bus("memq://");
  FakeLearner learner(rc, 5);
  auto opt = rolloutOptions(2, 20);
  opt.await_params_s = 0.05;
  opt.learner_silence_pause_s = 0.3;
  opt.learner_silence_exit_s = 0.6;
  masa::lcmt_policy_params bad = learner.message(0);
  bad.params[0] = std::numeric_limits<float>::quiet_NaN();
  bus.subscribeRaw(transport::kRolloutChannel, [&](const void*, int) { bus.publish(transport::kPolicyChannel, bad); });
  actor::Actor actor(rc, opt, &bus);
  bus.publish(transport::kPolicyChannel, learner.message(0));
  EXPECT_LT(actor.run(), 20) << "malformed repeats kept the actor going as if its learner were alive";
  EXPECT_GT(actor.paramsRejected(), 0);
}

}  // namespace
}  // namespace masa
