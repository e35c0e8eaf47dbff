// Hindsight relabeling (learner/sac/hindsight.hpp, common/sim/goal_relabeling.hpp): TriFinger's
// relabeled reward, success and termination against the simulation stepped with that goal; future
// goals from the same episode at or after the step, also across interleaved streams and a wrapped
// ring; relabeled n-step returns; MASA's networks symmetric on relabeled batches where SA's are
// not; a goal the symmetry acts on otherwise refused; the config's refusals; the distributed
// learner's streams; and HER learning a sparse goal-reaching problem that the same learner
// without it does not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <sstream>
#include <vector>

#include <Eigen/Geometry>

#include "common/config/run_config.hpp"
#include "common/model/method.hpp"
#include "learner/offline/twin_q.hpp"
#include "learner/sac/hindsight.hpp"
#include "learner/sac/off_policy_rule.hpp"
#include "learner/sac/replay_buffer.hpp"
#include "learner/sac/sac_critic_maps.hpp"
#include "learner/sac/td3_trainer.hpp"
#include "config_error_support.hpp"
#include "model_test_support.hpp"
#include "task_test_support.hpp"

namespace masa::sac {
namespace {

using model::Method;

config::RunConfig runOf(std::vector<std::string> sets) {
  return config::loadRunConfig(std::string(MASA_SOURCE_DIR) + "/configs", sets);
}

// ---------------------------------------------------------------- TriFinger's relabeling

// The goal pose in a saved task state: the last 7 numbers (the task's extras).
void setGoal(task::Task& t, const float* goal7) {
  std::vector<double> state;
  t.saveState(state);
  Eigen::Quaterniond q(goal7[3], goal7[4], goal7[5], goal7[6]);
  q.normalize();
  const double g[7] = {goal7[0], goal7[1], goal7[2], q.w(), q.x(), q.y(), q.z()};
  std::copy(g, g + 7, state.end() - 7);
  t.loadState(state);
}

TEST(Hindsight, TrifingerRelabeledRewardSuccessAndTerminationAreTheSimulationsForThatGoal) {
  const task::TaskFactory f = test::runConfigFactory("trifinger_lift");
  auto env = f.create(), other = f.create();
  const auto relabeling = env->goalRelabeling();
  ASSERT_NE(relabeling, nullptr);
  const int d = env->obsDim();
  Rng rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> act(9), obs(d), next(d), goal(7), other_obs(d);
  int successes = 0;
  for (int trial = 0; trial < 40; ++trial) {
    env->reset(rng);
    for (int k = 0; k < 20 + trial; ++k) {
      for (float& a : act) a = u(rng);
      env->step(act.data());
    }
    for (float& a : act) a = u(rng);
    std::vector<double> before;
    env->saveState(before);
    env->observe(obs.data());
    const task::StepOutcome out = env->step(act.data());
    env->observe(next.data());
    // The new goal: what the step achieved (every fourth trial), else another episode's goal.
    if (trial % 4 == 0) {
      std::copy(next.begin(), next.begin() + 7, goal.begin());
    } else {
      other->reset(rng);
      other->observe(other_obs.data());
      std::copy(other_obs.begin() + 7, other_obs.begin() + 14, goal.begin());
    }
    const task::RelabeledStep r = relabeling->relabel(obs.data(), next.data(), out.reward, out.terminated, goal.data());
    // The same step with that goal set in the simulation.
    env->loadState(before);
    setGoal(*env, goal.data());
    const task::StepOutcome truth = env->step(act.data());
    EXPECT_NEAR(r.reward, truth.reward, 1e-4 * (1.0 + std::abs(truth.reward))) << "trial " << trial;
    EXPECT_EQ(r.terminated, truth.terminated) << "trial " << trial;
    EXPECT_EQ(r.success, env->episode().success) << "trial " << trial;
    successes += r.success;
  }
  EXPECT_GE(successes, 10);  // the achieved goals succeed
  // A terminating step keeps its termination reward whatever the goal.
  const task::RelabeledStep t = relabeling->relabel(obs.data(), next.data(), -1.0, true, goal.data());
  EXPECT_TRUE(t.terminated);
  EXPECT_EQ(t.reward, -1.0);
}

TEST(Hindsight, TasksWithoutAGoalDeclareNone) {
  for (const char* name : {"a1_beam", "ant_acrobatic", "humanoid_tightrope", "humanoid_dribbling"})
    EXPECT_EQ(test::runConfigFactory(name).create()->goalRelabeling(), nullptr) << name;
}

// ---------------------------------------------------------------- the replay's episodes

// A step whose observation is (episode, step, step), next observation (episode, step + 1, step + 1).
void addEpisodeStep(ReplayBuffer& rb, long long episode, int step, bool end = false) {
  const float o[3] = {static_cast<float>(episode), static_cast<float>(step), static_cast<float>(step)};
  const float n[3] = {static_cast<float>(episode), static_cast<float>(step + 1), static_cast<float>(step + 1)};
  const float a[1] = {0.0f};
  rb.add(o, a, step, n, false, end, episode);
}

TEST(Hindsight, FutureSlotsAreOfTheSameEpisodeAtOrAfterTheStepWithinTheWindowAcrossInterleavedStreams) {
  ReplayBuffer rb(3, 1, 1000);
  // Three episodes in stretches of 5 interleaved, as the distributed learner stores them.
  for (int stretch = 0; stretch < 6; ++stretch)
    for (long long ep = 0; ep < 3; ++ep)
      for (int k = 0; k < 5; ++k) addEpisodeStep(rb, ep, 5 * stretch + k, k == 4);
  Rng rng(1);
  for (long long window : {0LL, 3LL}) {
    std::set<int> seen_offsets;
    for (int draw = 0; draw < 4000; ++draw) {
      const long long slot = std::uniform_int_distribution<long long>(0, rb.size() - 1)(rng);
      const long long f = rb.futureSlot(slot, window, rng);
      EXPECT_EQ(rb.episodeAt(f), rb.episodeAt(slot));
      const int offset = static_cast<int>(rb.obsAt(f)[1] - rb.obsAt(slot)[1]);
      ASSERT_GE(offset, 0);
      if (window > 0) {
        ASSERT_LE(offset, window);
      }
      seen_offsets.insert(offset);
    }
    // Every offset is reachable: the whole remaining episode (29 steps) or the window.
    EXPECT_EQ(static_cast<int>(seen_offsets.size()), window > 0 ? 4 : 30) << "window " << window;
  }
}

TEST(Hindsight, AWrappedRingForgetsOverwrittenStepsOfAnEpisode) {
  ReplayBuffer rb(3, 1, 10);
  for (int k = 0; k < 16; ++k) addEpisodeStep(rb, 7, k);  // one long episode; steps 0-5 overwritten
  Rng rng(2);
  for (int draw = 0; draw < 500; ++draw) {
    const long long slot = std::uniform_int_distribution<long long>(0, rb.size() - 1)(rng);
    const long long f = rb.futureSlot(slot, 0, rng);
    EXPECT_GE(rb.obsAt(f)[1], rb.obsAt(slot)[1]);
    EXPECT_GE(rb.obsAt(f)[1], 6.0f);
  }
  // One stream's own count: a new episode after an end.
  ReplayBuffer stream(3, 1, 10);
  const float o[3] = {0, 0, 0}, a[1] = {0};
  stream.add(o, a, 0, o, false, false);
  stream.add(o, a, 0, o, true, false);
  stream.add(o, a, 0, o, false, false);
  EXPECT_EQ(stream.episodeAt(stream.slotOfAge(2)), 0);
  EXPECT_EQ(stream.episodeAt(stream.slotOfAge(1)), 0);
  EXPECT_EQ(stream.episodeAt(stream.slotOfAge(0)), 1);
}

TEST(Hindsight, EpisodesSurviveSaveAndLoadAndAVersionOneBufferReadsAsOneStream) {
  ReplayBuffer rb(3, 1, 50);
  for (int stretch = 0; stretch < 4; ++stretch)
    for (long long ep = 0; ep < 2; ++ep)
      for (int k = 0; k < 5; ++k) addEpisodeStep(rb, ep, 5 * stretch + k, k == 4);
  std::stringstream ss;
  rb.save(ss);
  const std::string bytes = ss.str();
  ReplayBuffer back(3, 1, 50);
  std::stringstream in(bytes);
  back.load(in);
  Rng r1(5), r2(5);
  for (long long slot = 0; slot < rb.size(); ++slot) {
    EXPECT_EQ(back.episodeAt(slot), rb.episodeAt(slot));
    EXPECT_EQ(back.futureSlot(slot, 0, r2), rb.futureSlot(slot, 0, r1));
  }
  // Version 1: no episode array; each stretch end (a truncation) starts a new episode.
  std::string v1 = bytes.substr(0, bytes.size() - sizeof(long long) * rb.size());
  v1[7] = '1';
  ReplayBuffer old(3, 1, 50);
  std::stringstream in1(v1);
  old.load(in1);
  for (long long slot = 0; slot < old.size(); ++slot) EXPECT_EQ(old.episodeAt(slot), slot / 5);
}

// ---------------------------------------------------------------- relabeled n-step returns

// Goal entry 2 against achieved entry 1 (the step count): reward -|achieved - goal|, terminated
// when they meet.
class StepCountGoal final : public task::GoalRelabeling {
 public:
  const std::vector<int>& goalEntries() const override { return goal_; }
  const std::vector<int>& achievedEntries() const override { return achieved_; }
  task::RelabeledStep relabel(const float*, const float* next_obs, double, bool, const float* goal) const override {
    task::RelabeledStep s;
    s.reward = -std::abs(next_obs[1] - goal[0]);
    s.terminated = s.success = next_obs[1] == goal[0];
    return s;
  }

 private:
  std::vector<int> goal_{2}, achieved_{1};
};

TEST(Hindsight, ARelabeledNStepReturnSumsEachStepsRelabeledRewardAndStopsAtItsTermination) {
  ReplayBuffer rb(3, 1, 100);
  for (int k = 0; k < 10; ++k) addEpisodeStep(rb, 0, k, k == 9);
  const StepCountGoal goal_fn;
  ReplayBatch<double> batch;
  batch.resize(3, 1, 1);
  // From step 2 with goal 7, 4-step: rewards -|3-7|, -|4-7|, -|5-7|, -|6-7| at discount 0.5.
  const float goal7[1] = {7.0f};
  const GoalOverride g7{&goal_fn, goal7};
  rb.nStep(2, 4, 0.5, batch, 0, &g7);
  EXPECT_DOUBLE_EQ(batch.rewards(0, 0), -4 - 0.5 * 3 - 0.25 * 2 - 0.125 * 1);
  EXPECT_DOUBLE_EQ(batch.discount(0, 0), 0.0625);
  EXPECT_EQ(batch.obs(2, 0), 7.0);  // the goal written into both observations
  EXPECT_EQ(batch.next_obs(2, 0), 7.0);
  EXPECT_EQ(batch.next_obs(1, 0), 6.0);
  // Goal 4 is reached on the second step: the return stops there with discount 0.
  const float goal4[1] = {4.0f};
  const GoalOverride g4{&goal_fn, goal4};
  rb.nStep(2, 4, 0.5, batch, 0, &g4);
  EXPECT_DOUBLE_EQ(batch.rewards(0, 0), -1.0 + 0.5 * 0.0);
  EXPECT_DOUBLE_EQ(batch.discount(0, 0), 0.0);
}

// ---------------------------------------------------------------- MASA on relabeled batches

// TriFinger transitions under random actions, in one stream.
ReplayBuffer trifingerReplay(int steps) {
  const task::TaskFactory f = test::runConfigFactory("trifinger_lift");
  auto env = f.create();
  ReplayBuffer rb(env->obsDim(), env->actDim(), steps);
  Rng rng(8);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> obs(env->obsDim()), next(env->obsDim()), act(env->actDim());
  env->reset(rng);
  env->observe(obs.data());
  for (int t = 0; t < steps; ++t) {
    for (float& a : act) a = u(rng);
    const task::StepOutcome out = env->step(act.data());
    env->observe(next.data());
    rb.add(obs.data(), act.data(), out.reward, next.data(), out.terminated, out.truncated || t % 100 == 99);
    if (t % 100 == 99) env->reset(rng);
    env->observe(obs.data());
  }
  return rb;
}

struct NetworkSymmetry {
  double policy = 0, q = 0;
};

NetworkSymmetry symmetryOn(const sym::SymmetrySpec& spec, Method method, const ReplayBatch<float>& batch) {
  Rng rng(4);
  SacPolicyShape shape;
  shape.method = method;
  shape.hidden = {16, 12};
  SacPolicy<float> p(spec, shape);
  p.initialize(rng, 1.0f);
  offline::TwinQ<float> q(spec, twinQMaps(method, spec), {16, 12}, nn::Activation::kElu);
  q.initialize(rng);
  const int o = spec.obsDim(), a = spec.actDim(), b = batch.size();
  p.forward(batch.obs);
  const Mat<float> mean = p.mean();
  const Mat<float> q0 = q.forward(batch.obs, batch.actions);
  Mat<float> tobs(o, b), tact(a, b), tmean(a, b);
  NetworkSymmetry worst;
  auto rel = [](const Mat<float>& x, const Mat<float>& ref) {
    return static_cast<double>(((x - ref).array().abs() / (1 + ref.array().abs())).maxCoeff());
  };
  for (int i = 1; i < spec.numAgents(); ++i) {
    spec.obsTransform(i).apply<float>(batch.obs, tobs);
    spec.actTransform(i).apply<float>(batch.actions, tact);
    spec.actTransform(i).apply<float>(mean, tmean);
    p.forward(tobs);
    worst.policy = std::max(worst.policy, rel(p.mean(), tmean));
    worst.q = std::max(worst.q, rel(q.forward(tobs, tact), q0));
  }
  return worst;
}

TEST(Hindsight, MasaIsEquivariantAndItsTwinQInvariantOnRelabeledBatchesWhereSaIsNot) {
  const auto spec = test::shippedSpec("trifinger_lift");
  const ReplayBuffer rb = trifingerReplay(600);
  const config::RunConfig rc = runOf({"task=trifinger_lift", "sac.her_share=1"});
  SacConfig sc = readSacConfig(rc);
  const Hindsight her(rc, sc, test::runConfigFactory("trifinger_lift").create()->goalRelabeling(), spec);
  ReplayBatch<float> batch;
  Rng rng(9);
  her.sample(rb, 64, 3, 0.99, rng, batch);
  // Every goal in the batch is one the cube reached: relabeled, not the episode's own.
  ReplayBatch<float> plain;
  Rng rng2(9);
  rb.sample(64, 3, 0.99, rng2, plain);
  EXPECT_GT((batch.obs.middleRows(7, 7) - plain.obs.middleRows(7, 7)).cwiseAbs().maxCoeff(), 1e-3f);
  const NetworkSymmetry masa = symmetryOn(spec, Method::kMasa, batch), sa = symmetryOn(spec, Method::kSa, batch);
  EXPECT_LT(masa.policy, 1e-5);
  EXPECT_LT(masa.q, 1e-5);
  EXPECT_GT(sa.policy, 1e-3);
  EXPECT_GT(sa.q, 1e-4);
}

// A goal that is a finger's joint angles against the cube's position: C3 permutes the fingers and
// rotates the cube, so relabeling would break the symmetry.
class MismatchedGoal final : public task::GoalRelabeling {
 public:
  const std::vector<int>& goalEntries() const override { return goal_; }
  const std::vector<int>& achievedEntries() const override { return achieved_; }
  task::RelabeledStep relabel(const float*, const float*, double r, bool t, const float*) const override { return {r, t, false}; }

 private:
  std::vector<int> goal_{14, 15, 16}, achieved_{0, 1, 2};
};

TEST(Hindsight, AGoalTheSymmetryActsOnOtherwiseThanOnWhatIsAchievedIsRefused) {
  const auto spec = test::shippedSpec("trifinger_lift");
  const config::RunConfig rc = runOf({"task=trifinger_lift", "sac.her_share=0.5"});
  try {
    const Hindsight her(rc, readSacConfig(rc), std::make_unique<MismatchedGoal>(), spec);
    FAIL() << "a goal the symmetry breaks was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("relabeling would break the symmetry"), std::string::npos) << e.what();
  }
  // TriFinger's own passes.
  EXPECT_NO_THROW(
      { const Hindsight her(rc, readSacConfig(rc), test::runConfigFactory("trifinger_lift").create()->goalRelabeling(), spec); });
}

// ---------------------------------------------------------------- refusals

TEST(Hindsight, RelabelingATaskWithoutAGoalOrAShareOutsideZeroToOneIsRefusedNamingTheKey) {
  const config::RunConfig rc = runOf({"task=a1_beam", "sac.her_share=0.5"});
  const ConfigError e = test::configErrorOf(
      [&] { const Hindsight her(rc, readSacConfig(rc), nullptr, test::shippedSpec("a1_beam")); });
  EXPECT_EQ(e.key(), "sac.her_share");
  EXPECT_NE(std::string(e.what()).find("declares no goal"), std::string::npos) << e.what();
  // The distributed learner's rule refuses it when it is built, before any data.
  Rng rng(1);
  EXPECT_EQ(test::configErrorOf([&] { const OffPolicyRule rule(rc, rng); }).key(), "sac.her_share");
  for (const char* bad : {"sac.her_share=1.5", "sac.her_share=-0.1", "sac.her_share=.nan"})
    EXPECT_EQ(test::configErrorOf([&] { readSacConfig(runOf({"task=trifinger_lift", bad})); }).key(), "sac.her_share") << bad;
  EXPECT_EQ(test::configErrorOf([&] { readSacConfig(runOf({"task=trifinger_lift", "sac.her_future_window=-1"})); }).key(),
            "sac.her_future_window");
}

// ---------------------------------------------------------------- the distributed learner's streams

TEST(Hindsight, TheDistributedLearnerKeepsAnEpisodeAcrossRoundsOnlyWhereAStretchStartsWhereItsLastEnded) {
  const config::RunConfig rc = runOf({"task=trifinger_lift", "learner=off_policy", "sac.her_share=0.8",
                                      "sac.policy_hidden=[8]", "sac.q_hidden=[8]", "sac.learning_starts=1000"});
  Rng rng(1);
  OffPolicyRule rule(rc, rng);
  const int E = 2, T = 4, d = 41, a = 9;
  rollout::Rollout b;
  b.allocate(E, T, d, a);
  auto fill = [&](float base) {
    for (int t = 0; t <= T; ++t)
      for (int e = 0; e < E; ++e)
        for (int k = 0; k < d; ++k) b.obsAt(t, e)[k] = base + 10.0f * e + t;
  };
  const std::vector<int64_t> streams = {5, 6};
  fill(0.0f);
  rule.learn(b, streams, rng);
  // Environment 0 goes on where it ended; environment 1 does not (a stretch was lost).
  for (int t = 0; t <= T; ++t)
    for (int k = 0; k < d; ++k) {
      b.obsAt(t, 0)[k] = 0.0f + T + t;
      b.obsAt(t, 1)[k] = 1000.0f + t;
    }
  rule.learn(b, streams, rng);
  const ReplayBuffer& rb = rule.replay();
  ASSERT_EQ(rb.size(), 16);
  // Stored environment by environment: [e0 r0][e1 r0][e0 r1][e1 r1], 4 steps each.
  EXPECT_EQ(rb.episodeAt(rb.slotOfAge(15)), rb.episodeAt(rb.slotOfAge(7)));  // e0: one episode
  EXPECT_NE(rb.episodeAt(rb.slotOfAge(11)), rb.episodeAt(rb.slotOfAge(3)));  // e1: a new one
  // Saved and loaded, the next stretch of environment 0 still continues its episode.
  std::stringstream ss;
  rule.save(ss);
  Rng rng2(1);
  OffPolicyRule back(rc, rng2);
  back.load(ss, "state");
  for (int t = 0; t <= T; ++t)
    for (int k = 0; k < d; ++k) b.obsAt(t, 0)[k] = 0.0f + 2 * T + t;
  back.learn(b, streams, rng2);
  EXPECT_EQ(back.replay().episodeAt(back.replay().slotOfAge(7)), rb.episodeAt(rb.slotOfAge(15)));
}

// ---------------------------------------------------------------- HER learns where the learner alone does not

// A point in [-1, 1]^2 moved by 0.2 a per step towards a goal drawn in the same square; reward -1
// until it is within 0.1 of the goal, then 0 (terminal). 10 steps an episode.
const char* kPointReachSpec = R"(
name: point_reach
group: {type: reflection, axis: y}
observation:
  central:
    - {name: pos, kind: vector2}
    - {name: goal, kind: vector2}
action:
  central:
    - {name: move, kind: vector2}
)";

class PointGoal final : public task::GoalRelabeling {
 public:
  const std::vector<int>& goalEntries() const override { return goal_; }
  const std::vector<int>& achievedEntries() const override { return achieved_; }
  task::RelabeledStep relabel(const float*, const float* next_obs, double, bool, const float* goal) const override {
    return outcome(next_obs, goal);
  }
  static task::RelabeledStep outcome(const float* next_obs, const float* goal) {
    const bool reached = std::hypot(next_obs[0] - goal[0], next_obs[1] - goal[1]) < 0.1;
    return {reached ? 0.0 : -1.0, reached, reached};
  }

 private:
  std::vector<int> goal_{2, 3}, achieved_{0, 1};
};

// Success rate of the deterministic policy after `steps` environment steps of TD3.
double pointReachSuccess(double her_share) {
  const auto spec = test::spec(kPointReachSpec, "spec");
  SacPolicyShape shape;
  shape.method = Method::kSa;
  shape.hidden = {64, 64};
  SacPolicy<float> policy(spec, shape);
  offline::TwinQ<float> q(spec, twinQMaps(Method::kSa, spec), {64, 64}, nn::Activation::kElu),
      q_target(spec, twinQMaps(Method::kSa, spec), {64, 64}, nn::Activation::kElu);
  SacConfig sc;
  sc.policy_lr = sc.q_lr = 1e-3;
  sc.discount = 0.9;
  sc.td3_exploration_noise = 0.3;
  sc.her_share = her_share;
  Td3Trainer<float> trainer(spec, policy, q, q_target, sc);
  Rng rng(11);
  policy.initialize(rng);
  q.initialize(rng);
  q_target.moveTowards(q, 1.0f);
  config::RunConfig rc;
  rc.task = "point_reach";
  const Hindsight her(rc, sc, std::make_unique<PointGoal>(), spec);
  ReplayBuffer rb(4, 2, 20000);
  ReplayBatch<float> batch;
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> obs(4), next(4), act(2);
  auto run_episode = [&](bool explore, Rng& r) {
    obs = {u(r), u(r), u(r), u(r)};
    for (int t = 0; t < 10; ++t) {
      const Eigen::Map<const Mat<float>> o(obs.data(), 4, 1);
      Eigen::Map<Mat<float>> a(act.data(), 2, 1);
      if (explore) trainer.explore(o, r, a);
      else policy.actDeterministic(o, a);
      next = obs;
      for (int k = 0; k < 2; ++k) next[k] = std::clamp(obs[k] + 0.2f * act[k], -1.0f, 1.0f);
      const task::RelabeledStep s = PointGoal::outcome(next.data(), obs.data() + 2);
      if (explore) {
        rb.add(obs.data(), act.data(), s.reward, next.data(), s.terminated, t == 9);
        for (int g = 0; g < 2; ++g) {
          her.sample(rb, 128, 1, sc.discount, r, batch);
          trainer.step(batch, r);
        }
      }
      if (s.terminated) return true;
      obs = next;
    }
    return false;
  };
  for (int episode = 0; episode < 250; ++episode) run_episode(true, rng);
  Rng eval(99);
  int reached = 0;
  for (int k = 0; k < 100; ++k) reached += run_episode(false, eval);
  return reached / 100.0;
}

TEST(Hindsight, HerLearnsASparseGoalReachingProblemThatTheSameLearnerWithoutItDoesNot) {
  const double with_her = pointReachSuccess(0.8), without = pointReachSuccess(0.0);
  std::printf("point reach: success %.2f with HER, %.2f without\n", with_her, without);
  EXPECT_GE(with_her, 0.7) << "without: " << without;
  EXPECT_LE(without, 0.35) << "with: " << with_her;
  EXPECT_GT(with_her, without + 0.3);
}

}  // namespace
}  // namespace masa::sac
