// The YAML task of issue #13 item 1 against its C++ twins: configs/tasks/ant_acrobatic_yaml.yaml
// (balance: torques, free bodies, relative heights) and configs/tasks/a1_beam_yaml.yaml
// (locomotion: PD loop around a stand pose, Euler angles, a beam) describe two shipped tasks without
// task code. Each pair is reset with the same seeds and stepped with the same random actions, across
// episode ends; observations, every reward term and the termination must agree to 1e-6.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "task_test_support.hpp"

namespace masa::task {
namespace {

constexpr double kTwinTol = 1e-6;

struct TwinRun {
  int steps = 0, episodes = 0, terminations = 0;
  double worst_obs = 0.0, worst_term = 0.0;
  int outcome_mismatches = 0;
};

// Steps the C++ task and the YAML task side by side; `yaml_overrides` edit the YAML task's config.
TwinRun runTwins(const std::string& task, std::uint64_t seed, int steps,
                 const std::vector<std::string>& yaml_overrides = {}, const std::vector<std::string>& cpp_overrides = {}) {
  const TaskFactory cpp_factory = test::runConfigFactory(task, cpp_overrides);
  const TaskFactory yaml_factory = test::runConfigFactory(task + "_yaml", yaml_overrides);
  auto cpp = cpp_factory.create();
  auto yaml = yaml_factory.create();
  EXPECT_EQ(yaml->obsDim(), cpp->obsDim());
  EXPECT_EQ(yaml->rewardTermNames(), cpp->rewardTermNames());
  Rng cpp_rng(seed), yaml_rng(seed), action_rng(seed + 1);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> act(cpp->actDim()), o_cpp(cpp->obsDim()), o_yaml(yaml->obsDim());
  TwinRun run;
  auto compareObservations = [&] {
    cpp->observe(o_cpp.data());
    yaml->observe(o_yaml.data());
    for (int d = 0; d < cpp->obsDim(); ++d)
      run.worst_obs = std::max(run.worst_obs, std::abs(double(o_cpp[d]) - double(o_yaml[d])));
  };
  cpp->reset(cpp_rng);
  yaml->reset(yaml_rng);
  compareObservations();
  for (int s = 0; s < steps; ++s, ++run.steps) {
    for (float& a : act) a = u(action_rng);
    const StepOutcome a = cpp->step(act.data()), b = yaml->step(act.data());
    compareObservations();
    for (std::size_t k = 0; k < cpp->rewardTerms().size(); ++k)
      run.worst_term = std::max(run.worst_term, std::abs(cpp->rewardTerms()[k] - yaml->rewardTerms()[k]));
    run.worst_term = std::max(run.worst_term, std::abs(a.reward - b.reward));
    if (a.terminated != b.terminated || a.truncated != b.truncated) ++run.outcome_mismatches;
    if (a.terminated || a.truncated) {
      ++run.episodes;
      run.terminations += a.terminated;
      cpp->reset(cpp_rng);
      yaml->reset(yaml_rng);
      compareObservations();
    }
  }
  return run;
}

// Two seeds, 400 steps each, across the resets of episodes ended by falls.
void expectTwinsMatch(const std::string& task) {
  for (std::uint64_t seed : {0u, 7u}) {
    const TwinRun run = runTwins(task, seed, 400);
    EXPECT_LT(run.worst_obs, kTwinTol) << task << " seed " << seed;
    EXPECT_LT(run.worst_term, kTwinTol) << task << " seed " << seed;
    EXPECT_EQ(run.outcome_mismatches, 0) << task << " seed " << seed;
    EXPECT_GE(run.terminations, 3) << task << " seed " << seed;
  }
}

TEST(YamlTaskTwin, AntAcrobaticInYamlMatchesItsCppTaskTermByTerm) { expectTwinsMatch("ant_acrobatic"); }

TEST(YamlTaskTwin, A1BeamInYamlMatchesItsCppTaskTermByTerm) {
  expectTwinsMatch("a1_beam");
  // Stiff gains drive the torques into their limits (clamped by the PD loop, and by MuJoCo to ctrlrange).
  const TwinRun stiff = runTwins("a1_beam", 3, 200, {"env.actuation.kp=400"}, {"env.kp=400"});
  EXPECT_LT(stiff.worst_obs, kTwinTol);
  EXPECT_LT(stiff.worst_term, kTwinTol);
  EXPECT_EQ(stiff.outcome_mismatches, 0);
}

// What masa_deploy sends a robot: the same PD command from both, and none from a torque task.
TEST(YamlTaskTwin, A1BeamInYamlGivesTheSameJointCommand) {
  const auto cpp = test::runConfigFactory("a1_beam").create();
  const auto yaml = test::runConfigFactory("a1_beam_yaml").create();
  Rng rng(4);
  std::uniform_real_distribution<double> u(-1.5, 1.5);  // beyond [-1, 1]: the clamp too
  const int n = cpp->actDim();
  std::vector<double> action(n), a(5 * n), b(5 * n);
  for (double& x : action) x = u(rng);
  ASSERT_TRUE(cpp->jointCommand(action.data(), &a[0], &a[n], &a[2 * n], &a[3 * n], &a[4 * n]));
  ASSERT_TRUE(yaml->jointCommand(action.data(), &b[0], &b[n], &b[2 * n], &b[3 * n], &b[4 * n]));
  EXPECT_EQ(a, b);
  EXPECT_FALSE(test::runConfigFactory("ant_acrobatic_yaml").create()->jointCommand(action.data(), &b[0], &b[n],
                                                                                   &b[2 * n], &b[3 * n], &b[4 * n]));
}

// The comparison can fail: a threshold of the YAML description moved, or its reset changed, and
// the twins part.
TEST(YamlTaskTwin, ADifferenceInTheDescriptionIsSeen) {
  const TwinRun tilt = runTwins("ant_acrobatic", 0, 400, {"env.termination.pole_tilted.min=0.99"});
  EXPECT_GT(tilt.outcome_mismatches, 0);
  const TwinRun pose = runTwins("ant_acrobatic", 0, 50, {"env.pose.ankle=1.40"});
  EXPECT_GT(pose.worst_obs, 1e-3);
  const TwinRun weight = runTwins("ant_acrobatic", 0, 50, {"env.weights.energy=-0.06"});
  EXPECT_GT(weight.worst_term, 1e-6);
  const TwinRun gain = runTwins("a1_beam", 0, 50, {"env.actuation.kp=41"});
  EXPECT_GT(gain.worst_obs, 1e-4);
  const TwinRun target = runTwins("a1_beam", 0, 50, {"env.reward.velocity.target=0.6"});
  EXPECT_GT(target.worst_term, 1e-6);
}

}  // namespace
}  // namespace masa::task
