// The learner process over an in-process memq:// transport, fed by a fake actor: synthetic but
// valid rollouts of the TriFinger spec's dimensions, chunked as a real actor chunks them.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <thread>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "common/config/run_config.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/message_auth.hpp"
#include "actors/rollout_chunker.hpp"
#include "learner/learner.hpp"
#include "learner/ppo_algorithm.hpp"
#include "learner/run_dir/run_directory.hpp"
#include "masa/lcmt_actor_heartbeat.hpp"
#include "masa/lcmt_learner_stats.hpp"
#include "masa/lcmt_policy_params.hpp"

namespace masa::learner {
namespace {

namespace fs = std::filesystem;

config::RunConfig smallLearnerConfig() {
  return config::loadRunConfig(config::defaultConfigsDir(),
                               {"task=trifinger_lift", "model.policy_hidden=[16]", "model.critic_hidden=[16]",
                                "ppo.num_envs=8", "ppo.horizon=4", "ppo.minibatch_size=16", "ppo.mini_epochs=1"});
}

fs::path freshDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("masa_test_learner_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

LearnerOptions nodeOptions(const fs::path& dir, int64_t run_id) {
  LearnerOptions o;
  o.make_algorithm = makePpoAlgorithm;
  o.url = "memq://";
  o.run_dir = dir.string();
  o.run_id = run_id;
  o.verbose = false;
  return o;
}

// A fake actor: a consistent Gaussian policy (mean 0, log std 0) with one time-out and one episode.
struct FakeActor {
  rollout::Rollout rollout;
  actor::RolloutChunker chunker;

  FakeActor(const config::RunConfig& rc, uint64_t seed) {
    const auto spec = sym::SymmetrySpec::load(rc.spec_path);
    const int E = rc.rollout.num_envs, T = rc.rollout.horizon, od = spec.obsDim(), ad = spec.actDim();
    rollout.allocate(E, T, od, ad, {"keypoints", "reach", "termination"});  // the task's terms
    rollout.clearEvents();
    std::mt19937_64 rng(seed);
    std::normal_distribution<float> normal;
    for (float& x : rollout.obs) x = normal(rng);
    for (float& x : rollout.reward) x = normal(rng);
    for (float& x : rollout.mean) x = 0.0f;
    for (float& x : rollout.env_log_std) x = 0.0f;
    for (int t = 0; t < T; ++t) {
      for (int e = 0; e < E; ++e) {
        double lp = 0;
        float* a = rollout.actionAt(t, e);
        for (int k = 0; k < ad; ++k) {
          a[k] = normal(rng);
          lp += -0.5 * a[k] * a[k] - 0.5 * std::log(2 * M_PI);
        }
        rollout.log_prob[rollout.step(t, e)] = static_cast<float>(lp);
      }
    }
    std::vector<float> final_obs(od, 0.5f);
    rollout.truncated[rollout.step(1, 2)] = 1;
    rollout.addFinal(1, 2, final_obs.data());
    const float terms[3] = {1.5f, -0.5f, 0.0f};
    rollout.addEpisode(2, 3.0f, 20, 1, terms);
  }

  // Publishes the rollout's chunks as actor 0's rollout `seq`, acted with `version`.
  // Chunks `keep` says no to are lost on the way.
  int send(transport::MessageBus& t, int64_t run_id, int64_t seq, int64_t version,
           const std::function<bool(int chunk_index)>& keep = {}) {
    const auto chunks = chunker.split(rollout, {run_id, 0, seq, version});
    for (const auto& c : chunks)
      if (!keep || keep(c.chunk_index)) t.publish(transport::kRolloutChannel, c);
    return static_cast<int>(chunks.size());
  }
};

// Steps until an update runs (or gives up), then lets the published messages reach subscribers.
bool stepUntilUpdate(Learner& l, int max_steps = 200) {
  bool updated = false;
  for (int i = 0; i < max_steps && !updated; ++i) updated = l.step(0);
  for (int i = 0; i < 5; ++i) l.step(0);
  return updated;
}

std::vector<std::string> readLines(const fs::path& p) {
  std::ifstream f(p);
  std::vector<std::string> lines;
  for (std::string s; std::getline(f, s);) lines.push_back(s);
  return lines;
}

TEST(LearnerNode, OneBatchFromAFakeActorMakesVersionOneAndPublishesParamsStatsAndMetrics) {
  const auto rc = smallLearnerConfig();
  const fs::path dir = freshDir("update");
  Learner learner(rc, nodeOptions(dir, 77));
  masa::lcmt_policy_params params;
  masa::lcmt_learner_stats stats;
  int num_stats = 0;
  learner.transport().subscribe<masa::lcmt_policy_params>(transport::kPolicyChannel,
                                                          [&](const masa::lcmt_policy_params& m) { params = m; });
  learner.transport().subscribe<masa::lcmt_learner_stats>(transport::kLearnerStatsChannel,
                                                          [&](const masa::lcmt_learner_stats& m) {
                                                            stats = m;
                                                            ++num_stats;
                                                          });
  FakeActor actor(rc, 1);
  actor.send(learner.transport(), 77, 0, 0);
  ASSERT_TRUE(stepUntilUpdate(learner));

  EXPECT_EQ(learner.version(), 1);
  EXPECT_EQ(learner.updates(), 1);
  EXPECT_EQ(learner.envSteps(), 8 * 4);
  EXPECT_EQ(params.version, 1);
  EXPECT_EQ(params.run_id, 77);
  EXPECT_EQ(params.task, "trifinger_lift");
  const auto& p = learner.algorithm().evaluationModel().params().values();
  const int policy = learner.algorithm().evaluationModel().policyParamCount();
  ASSERT_LT(policy, p.size()) << "the critic is not broadcast";
  ASSERT_EQ(params.num_params, policy);
  EXPECT_EQ(std::memcmp(params.params.data(), p.data(), policy * sizeof(float)), 0);
  EXPECT_EQ(params.obs_dim, learner.algorithm().evaluationModel().obsDim());
  for (float s : params.obs_std) EXPECT_GT(s, 0.0f);

  ASSERT_EQ(num_stats, 1);
  EXPECT_EQ(stats.update, 1);
  EXPECT_EQ(stats.env_steps, 32);
  EXPECT_EQ(stats.num_episodes, 1);
  EXPECT_FLOAT_EQ(stats.mean_episode_return, 3.0f);
  EXPECT_FLOAT_EQ(stats.success_rate, 1.0f);
  ASSERT_EQ(stats.num_terms, 3);
  EXPECT_EQ(stats.term_names[0], "keypoints");
  EXPECT_FLOAT_EQ(stats.term_means[1], -0.5f);
  EXPECT_TRUE(std::isfinite(stats.actor_loss) && std::isfinite(stats.critic_loss));
  EXPECT_GT(stats.learning_rate, 0.0f);

  const auto lines = readLines(dir / "metrics.csv");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].rfind("update,env_steps,wall_time_s,fps,return,length,success,term_keypoints", 0), 0u);
  EXPECT_EQ(lines[1].rfind("1,32,", 0), 0u);
  EXPECT_TRUE(fs::exists(dir / "config.yaml"));
  fs::remove_all(dir);
}

TEST(LearnerNode, ChunksOfAnotherRunAndHostileChunksAreDroppedCountedAndNeverTriggerAnUpdate) {
  const auto rc = smallLearnerConfig();
  const fs::path dir = freshDir("drops");
  Learner learner(rc, nodeOptions(dir, 5));
  masa::lcmt_learner_stats stats;
  learner.transport().subscribe<masa::lcmt_learner_stats>(
      transport::kLearnerStatsChannel, [&](const masa::lcmt_learner_stats& m) { stats = m; });
  FakeActor actor(rc, 2);
  // A full batch of another run.
  const int foreign = actor.send(learner.transport(), 6, 0, 0);
  // Garbage bytes, and a whole batch of this run poisoned with a NaN in every chunk.
  const char junk[] = "definitely not an lcmt_rollout_chunk";
  learner.transport().publishRaw(transport::kRolloutChannel, junk, sizeof(junk));
  FakeActor poisoned(rc, 3);
  for (float& x : poisoned.rollout.reward) x = std::nanf("");
  const int nan_chunks = poisoned.send(learner.transport(), 5, 0, 0);
  EXPECT_FALSE(stepUntilUpdate(learner, 50));
  EXPECT_EQ(learner.version(), 0);
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kWrongRun], foreign);
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kMalformed], 1);
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kNonFinite], nan_chunks);
  EXPECT_FALSE(fs::exists(dir / "metrics.csv"));

  // The next good batch goes through, and its stats carry the drops.
  actor.send(learner.transport(), 5, 1, 0);
  ASSERT_TRUE(stepUntilUpdate(learner));
  ASSERT_EQ(stats.update, 1);
  auto countOf = [&](const std::string& name) {
    for (int i = 0; i < stats.num_drop_reasons; ++i)
      if (stats.drop_reason_names[i] == name) return stats.drop_counts[i];
    return int64_t{-1};
  };
  EXPECT_EQ(countOf("wrong_run"), foreign);
  EXPECT_EQ(countOf("malformed"), 1);
  EXPECT_EQ(countOf("non_finite"), nan_chunks);
  EXPECT_EQ(learner.droppedChunks(), foreign + 1 + nan_chunks);
  EXPECT_EQ(learner.droppedEnvs(), 0);
  // metrics.csv: chunks and environments in columns of their own, never added together.
  const auto lines = readLines(dir / "metrics.csv");
  ASSERT_EQ(lines.size(), 2u);
  auto cell = [&](const std::string& column) {
    std::vector<std::string> head, row;
    for (auto [line, out] : {std::pair{&lines[0], &head}, std::pair{&lines[1], &row}}) {
      std::stringstream ss(*line);
      for (std::string f; std::getline(ss, f, ',');) out->push_back(f);
    }
    for (std::size_t i = 0; i < head.size() && i < row.size(); ++i)
      if (head[i] == column) return row[i];
    return std::string("(no column ") + column + ")";
  };
  EXPECT_EQ(cell("dropped_chunks"), std::to_string(foreign + 1 + nan_chunks));
  EXPECT_EQ(cell("dropped_envs"), "0");
  EXPECT_EQ(cell("dropped"), "(no column dropped)");
  fs::remove_all(dir);
}

TEST(LearnerNode, WithARunKeyChunksSignedWithAnotherKeyAreCountedUnauthenticatedAndTheRunKeysAreTrainedOn) {
  const auto rc = smallLearnerConfig();
  const fs::path dir = freshDir("auth");
  LearnerOptions o = nodeOptions(dir, 8);
  o.run_key = transport::RunKey::random();
  Learner learner(rc, o);
  masa::lcmt_learner_stats stats;
  learner.transport().subscribe<masa::lcmt_learner_stats>(
      transport::kLearnerStatsChannel, [&](const masa::lcmt_learner_stats& m) { stats = m; });
  FakeActor actor(rc, 4);
  // A whole batch of this run, as an actor with another key sends it.
  const transport::MessageAuthenticator other(transport::RunKey::random());
  const auto chunks = actor.chunker.split(actor.rollout, {8, 0, 0, 0});
  for (const auto& c : chunks) {
    std::vector<uint8_t> bytes(c.getEncodedSize() + transport::kAuthTrailerBytes);
    const int size = c.encode(bytes.data(), 0, c.getEncodedSize());
    other.seal(transport::kRolloutChannel, bytes.data(), size, bytes.data() + size);
    dynamic_cast<transport::Transport&>(learner.transport()).publishWire(transport::kRolloutChannel, bytes.data(), static_cast<int>(bytes.size()));
  }
  const int forged = static_cast<int>(chunks.size());
  EXPECT_FALSE(stepUntilUpdate(learner, 50));
  EXPECT_EQ(learner.version(), 0);
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kUnauthenticated], forged);
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kAccepted], 0);

  // The same rollout, same numbering, signed with the run key: the forged copies left no trace.
  actor.send(learner.transport(), 8, 0, 0);
  ASSERT_TRUE(stepUntilUpdate(learner));
  EXPECT_EQ(learner.version(), 1);
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kDuplicate], 0);
  EXPECT_EQ(learner.droppedChunks(), forged);
  int64_t reported = -1;
  for (int i = 0; i < stats.num_drop_reasons; ++i)
    if (stats.drop_reason_names[i] == "unauthenticated") reported = stats.drop_counts[i];
  EXPECT_EQ(reported, forged) << "the stats message carries the count under its own reason";
  fs::remove_all(dir);
}

TEST(LearnerNode, ResumedLearnerMakesTheBitwiseSameNextUpdateAndContinuesTheCsv) {
  auto rc = smallLearnerConfig();
  rc.runner.checkpoint_every = 1;
  const fs::path dir_a = freshDir("ckpt_a"), dir_b = freshDir("ckpt_b");
  FakeActor first(rc, 10), second(rc, 11);
  std::vector<float> params_a;
  {
    Learner a(rc, nodeOptions(dir_a, 9));
    first.send(a.transport(), 9, 0, 0);
    ASSERT_TRUE(stepUntilUpdate(a));
    ASSERT_TRUE(fs::exists(dir_a / "checkpoint.bin"));
    fs::copy(dir_a, dir_b, fs::copy_options::recursive);  // the run as it was after update 1
    second.send(a.transport(), 9, 1, 1);
    ASSERT_TRUE(stepUntilUpdate(a));
    ASSERT_EQ(a.version(), 2);
    const auto& p = a.algorithm().evaluationModel().params().values();
    params_a.assign(p.data(), p.data() + p.size());
  }
  LearnerOptions o = nodeOptions(dir_b, 0);  // run id from the checkpoint
  o.resume = true;
  Learner b(rc, o);
  EXPECT_EQ(b.runId(), 9);
  EXPECT_EQ(b.version(), 1);
  EXPECT_EQ(b.envSteps(), 32);
  second.send(b.transport(), 9, 1, 1);
  ASSERT_TRUE(stepUntilUpdate(b));
  EXPECT_EQ(b.version(), 2);
  const auto& p = b.algorithm().evaluationModel().params().values();
  ASSERT_EQ(static_cast<std::size_t>(p.size()), params_a.size());
  EXPECT_EQ(std::memcmp(p.data(), params_a.data(), params_a.size() * sizeof(float)), 0);

  const auto lines = readLines(dir_b / "metrics.csv");
  ASSERT_EQ(lines.size(), 3u);  // one header, the row before the checkpoint, the resumed row
  EXPECT_EQ(lines[0].rfind("update,", 0), 0u);
  EXPECT_EQ(lines[2].rfind("2,64,", 0), 0u);
  fs::remove_all(dir_a);
  fs::remove_all(dir_b);
}

// The progress line's "learn Xs waited Ys": an update's own time, and the time its batch kept it
// waiting since the previous update ended (what tells a starved learner from a busy one).
TEST(LearnerNode, TheReportSaysHowLongTheUpdateLearnedAndHowLongItWaitedForItsBatch) {
  auto rc = smallLearnerConfig();
  const fs::path dir = freshDir("timing");
  FakeActor actor(rc, 10);
  Learner a(rc, nodeOptions(dir, 9));
  std::this_thread::sleep_for(std::chrono::milliseconds(150));  // the actors are late
  actor.send(a.transport(), 9, 0, 0);
  ASSERT_TRUE(stepUntilUpdate(a));
  const UpdateReport first = a.lastReport();
  EXPECT_GE(first.wait_s, 0.15);
  EXPECT_GT(first.learn_s, 0.0);
  EXPECT_LT(first.learn_s, first.wait_s) << "a tiny update outlasted the 150 ms wait";
  actor.send(a.transport(), 9, 1, 1);  // the next batch is there as soon as the update ends
  ASSERT_TRUE(stepUntilUpdate(a));
  const UpdateReport second = a.lastReport();
  EXPECT_LT(second.wait_s, 0.15);
  EXPECT_GT(second.learn_s, 0.0);
  fs::remove_all(dir);
}

// A second fresh run given the first one's directory: refused before anything is written, so the
// first run's checkpoint stays what a resume needs and its metrics.csv keeps one run's rows (the
// device probes of issue #30 repeated a point into one directory: three runs' rows in one file).
TEST(LearnerNode, AFreshRunInADirectoryThatHoldsARunIsRefusedAndTheRunIsUntouched) {
  auto rc = smallLearnerConfig();
  rc.runner.checkpoint_every = 1;
  const fs::path dir = freshDir("in_use");
  FakeActor actor(rc, 10);
  {
    Learner a(rc, nodeOptions(dir, 9));
    actor.send(a.transport(), 9, 0, 0);
    ASSERT_TRUE(stepUntilUpdate(a));
  }
  const auto read = [](const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  };
  const std::string checkpoint = read(dir / "checkpoint.bin"), metrics = read(dir / "metrics.csv");
  ASSERT_FALSE(checkpoint.empty());
  try {
    Learner b(rc, nodeOptions(dir, 10));
    FAIL() << "a fresh run was started in a directory holding a run";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(dir.string()), std::string::npos) << what;
    EXPECT_NE(what.find("checkpoint.bin"), std::string::npos) << what;
    EXPECT_NE(what.find("--resume"), std::string::npos) << what;
  }
  EXPECT_EQ(read(dir / "checkpoint.bin"), checkpoint);
  EXPECT_EQ(read(dir / "metrics.csv"), metrics);
  // Only the metrics of a run that never checkpointed: refused as well. An empty one, or a
  // directory of the launchers' files only, is a fresh start.
  fs::remove(dir / "checkpoint.bin");
  EXPECT_THROW(Learner(rc, nodeOptions(dir, 10)), std::runtime_error);
  std::ofstream(dir / "metrics.csv", std::ios::trunc).flush();
  std::ofstream(dir / "job_roster") << "launcher's file\n";
  EXPECT_NO_THROW(Learner(rc, nodeOptions(dir, 10)));
  fs::remove_all(dir);
}

// Without --run-dir a run gets runs/<name>_<seed>_<time>: the same command run again starts a new
// run beside the last instead of being refused by the guard above.
TEST(RunDirectory, TheDefaultNameCarriesTheSeedAndTheTimeOfTheStart) {
  const std::string dir = defaultRunDir("a1_beam_masa", 7);
  EXPECT_TRUE(std::regex_match(dir, std::regex("runs/a1_beam_masa_7_20[0-9]{6}-[0-9]{6}"))) << dir;
}

// kill -9 of the learner between two checkpoints: metrics.csv has rows for updates the checkpoint
// does not have. A resume cuts them off first, so every update has one row, in order.
TEST(LearnerNode, ResumeCutsMetricsCsvBackToTheCheckpointsUpdate) {
  auto rc = smallLearnerConfig();
  rc.runner.checkpoint_every = 1;
  const fs::path dir = freshDir("csv_cut"), saved = freshDir("csv_cut_ckpt");
  FakeActor actor(rc, 10);
  {
    Learner a(rc, nodeOptions(dir, 9));
    for (int k = 0; k < 10; ++k) {
      actor.send(a.transport(), 9, k, k);
      ASSERT_TRUE(stepUntilUpdate(a)) << "update " << k;
      if (k == 5) fs::copy(dir, saved, fs::copy_options::recursive);  // the checkpoint at update 6
    }
  }
  ASSERT_EQ(readLines(dir / "metrics.csv").size(), 11u);  // header, updates 1..10
  // The learner died after update 10's row but its newest checkpoint is update 6's.
  fs::copy_file(saved / "checkpoint.bin", dir / "checkpoint.bin", fs::copy_options::overwrite_existing);
  LearnerOptions o = nodeOptions(dir, 0);
  o.resume = true;
  Learner b(rc, o);
  ASSERT_EQ(b.version(), 6);
  auto lines = readLines(dir / "metrics.csv");
  ASSERT_EQ(lines.size(), 7u) << "header and updates 1..6";
  for (int k = 1; k <= 6; ++k) EXPECT_EQ(lines[k].rfind(std::to_string(k) + ",", 0), 0u) << lines[k];
  actor.send(b.transport(), 9, 6, 6);
  ASSERT_TRUE(stepUntilUpdate(b));
  lines = readLines(dir / "metrics.csv");
  ASSERT_EQ(lines.size(), 8u);
  EXPECT_EQ(lines[7].rfind("7,", 0), 0u) << lines[7];
  fs::remove_all(dir);
  fs::remove_all(saved);
}

// A lost chunk costs its own environments only: once the loss is known (its rollout's last chunk
// came, or nothing more of it within runner.loss_grace_s) the batch forms without them, instead of
// waiting for the actor's next rollout (the learner used to stall until then: 0.79 of the lossless
// update rate at 5% datagram loss on the namespace LAN).
TEST(LearnerNode, ABatchFormsShortOfLostChunksOnceTheirLossIsKnown) {
  auto rc = smallLearnerConfig();  // 8 environments x 4 steps, minibatches of 16
  rc.runner.loss_grace_s = 0.5;
  rc.runner.min_batch_fraction = 0.5;
  const fs::path dir = freshDir("short");
  Learner learner(rc, nodeOptions(dir, 21));
  FakeActor actor(rc, 7);
  actor.chunker = actor::RolloutChunker(1);  // one environment per chunk
  ASSERT_EQ(actor.send(learner.transport(), 21, 0, 0), 8);
  ASSERT_TRUE(stepUntilUpdate(learner)) << "a full batch";
  ASSERT_EQ(learner.envSteps(), 32);

  // Chunk 5 lost, the last one (7) came: the loss is known at once.
  actor.send(learner.transport(), 21, 1, 1, [](int c) { return c != 5; });
  ASSERT_TRUE(stepUntilUpdate(learner)) << "the learner waits for a chunk that is lost";
  EXPECT_EQ(learner.version(), 2);
  EXPECT_EQ(learner.envSteps(), 32 + 7 * 4);
  EXPECT_EQ(learner.shortBatches(), 1);

  // The last chunk lost: known when the grace has passed, not before.
  actor.send(learner.transport(), 21, 2, 2, [](int c) { return c != 7; });
  EXPECT_FALSE(stepUntilUpdate(learner, 20)) << "within the grace the chunk may still come";
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  ASSERT_TRUE(stepUntilUpdate(learner));
  EXPECT_EQ(learner.version(), 3);
  EXPECT_EQ(learner.envSteps(), 32 + 7 * 4 + 7 * 4);

  // Fewer than min_batch_fraction of the environments came: no batch, however long the wait.
  actor.send(learner.transport(), 21, 3, 3, [](int c) { return c < 3; });
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  EXPECT_FALSE(stepUntilUpdate(learner, 20));
  EXPECT_EQ(learner.version(), 3);
  actor.send(learner.transport(), 21, 4, 3);  // the actor's next rollout fills it
  ASSERT_TRUE(stepUntilUpdate(learner));
  EXPECT_EQ(learner.version(), 4);
  EXPECT_EQ(learner.shortBatches(), 2);
  fs::remove_all(dir);
}

// A parameter broadcast lost on its way to an actor (issue #33: on a lossy LAN a 215 KB broadcast
// is lost whole when any of its 4 fragments is) is repeated after runner.repeat_unacknowledged_s
// while a live actor has not acknowledged it, not only after runner.republish_every_s; the actor's
// acknowledging heartbeat ends the repeats, and heartbeats of another run or a wild actor id move
// nothing.
TEST(LearnerNode, ParametersAreRepeatedUntilEveryLiveActorAcknowledgesThem) {
  auto rc = smallLearnerConfig();
  rc.runner.republish_every_s = 30;  // the periodic republish out of the way
  rc.runner.repeat_unacknowledged_s = 0.05;
  const fs::path dir = freshDir("repeat");
  Learner learner(rc, nodeOptions(dir, 23));
  int broadcasts = 0;
  int64_t latest = -1;
  learner.transport().subscribe<masa::lcmt_policy_params>(transport::kPolicyChannel,
                                                          [&](const masa::lcmt_policy_params& m) {
                                                            ++broadcasts;
                                                            latest = m.version;
                                                          });
  auto heartbeat = [&](int64_t run_id, int actor_id, int64_t holds) {
    masa::lcmt_actor_heartbeat h{};
    h.run_id = run_id;
    h.actor_id = actor_id;
    h.hostname = "test";
    h.policy_version = holds;
    h.params_version = holds;
    learner.transport().publish(transport::kHeartbeatChannel, h);
  };
  auto stepFor = [&](double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) learner.step(5);
  };
  stepFor(0.1);
  broadcasts = 0;
  stepFor(0.3);
  EXPECT_EQ(broadcasts, 0) << "no actor known: only the periodic republish";

  heartbeat(24, 0, -1);        // another run
  heartbeat(23, -1, -1);       // ids the assembler would refuse
  heartbeat(23, 1 << 20, -1);
  heartbeat(23, 0, -7);        // no such version
  stepFor(0.3);
  EXPECT_EQ(broadcasts, 0) << "a heartbeat the learner does not believe moved the repeats";

  heartbeat(23, 0, -1);  // actor 0 is live and holds nothing: the initial broadcast was lost
  stepFor(0.3);          // repeats at 0, 75, 187 ms (then 356)
  EXPECT_GE(broadcasts, 2) << "the learner waited for its periodic republish";
  EXPECT_LE(broadcasts, 4) << "repeats come at growing intervals";
  learner.transport().drain();  // the last repeat, published in the last step
  EXPECT_EQ(latest, 0);
  EXPECT_EQ(learner.unacknowledgedRepeats(), broadcasts);

  heartbeat(23, 0, 0);  // acknowledged
  stepFor(0.05);
  broadcasts = 0;
  stepFor(0.3);
  EXPECT_EQ(broadcasts, 0) << "repeated after the acknowledgement";

  // An update: version 1 goes out, and is repeated until actor 0 says it holds it. Its rollout of
  // version 0 is no acknowledgement of version 1.
  FakeActor actor(rc, 3);
  actor.send(learner.transport(), 23, 0, 0);
  ASSERT_TRUE(stepUntilUpdate(learner));
  stepFor(0.2);
  EXPECT_EQ(latest, 1);
  EXPECT_GE(broadcasts, 2) << "the update's broadcast and at least one repeat";
  heartbeat(23, 0, 1);
  stepFor(0.05);
  broadcasts = 0;
  stepFor(0.3);
  EXPECT_EQ(broadcasts, 0);
  fs::remove_all(dir);
}

// The bookkeeping behind the repeats, without a clock.
TEST(ParamsDelivery, RepeatsForALiveActorThatHasNotAcknowledgedAtGrowingIntervalsUntilItDoesOrFallsSilent) {
  using Clock = ParamsDelivery::Clock;
  const Clock::time_point t0{};
  const auto ms = [](double x) { return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(x)); };
  ParamsDelivery d(0.1, 1.0, 3.0);
  d.published(5, t0);
  EXPECT_EQ(d.nextRepeat(t0), Clock::time_point::max()) << "nobody known";
  d.actorHolds(2, 4, t0 + ms(1));
  EXPECT_EQ(d.nextRepeat(t0 + ms(1)), t0 + ms(100));
  EXPECT_FALSE(d.repeatDue(t0 + ms(99)));
  EXPECT_TRUE(d.repeatDue(t0 + ms(100)));
  d.published(5, t0 + ms(100));
  EXPECT_EQ(d.nextRepeat(t0 + ms(100)), t0 + ms(250)) << "1.5x the interval";
  d.published(5, t0 + ms(250));
  EXPECT_EQ(d.nextRepeat(t0 + ms(250)), t0 + ms(475));
  for (int i = 0; i < 10; ++i) d.published(5, t0 + ms(500));
  EXPECT_EQ(d.nextRepeat(t0 + ms(500)), t0 + ms(1500)) << "at most max_repeat_s";

  d.actorHolds(2, 5, t0 + ms(600));  // acknowledged
  EXPECT_EQ(d.nextRepeat(t0 + ms(600)), Clock::time_point::max());
  d.actorHolds(2, 4, t0 + ms(610));  // a late chunk acted with the version before
  EXPECT_EQ(d.nextRepeat(t0 + ms(610)), Clock::time_point::max()) << "the acknowledgement stands";

  d.published(6, t0 + ms(700));  // a new version: the intervals start again
  EXPECT_EQ(d.nextRepeat(t0 + ms(700)), t0 + ms(800));
  EXPECT_EQ(d.nextRepeat(t0 + ms(610) + ms(3000)), t0 + ms(800)) << "live for 3 s after it was heard";
  EXPECT_EQ(d.nextRepeat(t0 + ms(611) + ms(3000)), Clock::time_point::max()) << "silent: not waited for";

  d.actorHolds(7, 9, t0 + ms(3700));  // holds a version the learner is not at (it resumed behind)
  EXPECT_NE(d.nextRepeat(t0 + ms(3700)), Clock::time_point::max());

  ParamsDelivery off(0.0, 1.0, 3.0);
  off.published(1, t0);
  off.actorHolds(0, -1, t0);
  EXPECT_EQ(off.nextRepeat(t0), Clock::time_point::max()) << "repeat_unacknowledged_s 0: never";
}

TEST(LearnerNode, AMinibatchSizeThatDoesNotDivideTheBatchIsRefusedByName) {
  auto rc = smallLearnerConfig();
  rc.ppo.minibatch_size = 12;  // 8 x 4 = 32 samples
  const fs::path dir = freshDir("mb");
  try {
    Learner learner(rc, nodeOptions(dir, 22));
    ADD_FAILURE() << "a learner was made";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("ppo.minibatch_size 12 must divide the batch"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace masa::learner
