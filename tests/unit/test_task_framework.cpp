// The task base class, registry and physics-symmetry verifier, on a small mirror-symmetric test
// robot (tests/data/twin_arm.xml) so that they are tested apart from the five real tasks.
#include <gtest/gtest.h>

#include <cmath>

#include "common/core/config_error.hpp"
#include "task_test_support.hpp"

namespace masa::task {
namespace {

using namespace masa::test;

const std::string kFrameworkData = MASA_TEST_DATA_DIR;

class TwinArmTask : public Task {
 public:
  TwinArmTask(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec, EnvParams& p)
      : Task("twin_arm_test", model, spec, p, {{"reach", 1.0}, {"effort", -0.1}}),
        terminate_below_(p.number("terminate_below", -1.0)),
        noise_(p.number("reset_noise", 0.1)) {
    ball_ = model_->id(mjOBJ_BODY, "ball");
    hands_[0] = model_->id(mjOBJ_GEOM, "right_hand");
    hands_[1] = model_->id(mjOBJ_GEOM, "left_hand");
  }

 protected:
  void resetTask(Rng& rng) override {
    std::uniform_real_distribution<double> u(-noise_, noise_);
    const mjModel* m = model();
    for (int j = 0; j < m->njnt; ++j)
      if (m->jnt_type[j] == mjJNT_HINGE) data_->qpos[m->jnt_qposadr[j]] += u(rng);
    for (int k = 0; k < m->nv; ++k) data_->qvel[k] = u(rng);
  }
  void writeObservation(float* out) const override {
    const mjModel* m = model();
    int o = 0;
    auto joint = [&](const char* name, bool vel) {
      const int j = mj_name2id(m, mjOBJ_JOINT, name);
      return vel ? data_->qvel[m->jnt_dofadr[j]] : data_->qpos[m->jnt_qposadr[j]];
    };
    out[o++] = joint("waist", false);
    out[o++] = joint("waist", true);
    const int bq = m->jnt_qposadr[m->body_jntadr[ball_]], bv = m->jnt_dofadr[m->body_jntadr[ball_]];
    for (int k = 0; k < 3; ++k) out[o++] = data_->qpos[bq + k];
    for (int k = 0; k < 3; ++k) out[o++] = data_->qvel[bv + k];
    // Ball angular velocity in the world frame (the free joint stores it in the body frame).
    double w[3];
    mju_mulMatVec(w, data_->xmat + 9 * ball_, data_->qvel + bv + 3, 3, 3);
    for (int k = 0; k < 3; ++k) out[o++] = w[k];
    const char* sides[2][2] = {{"right_shoulder", "right_elbow"}, {"left_shoulder", "left_elbow"}};
    for (int limb = 0; limb < 2; ++limb) {
      out[o++] = joint(sides[limb][0], false);
      out[o++] = joint(sides[limb][1], false);
      out[o++] = joint(sides[limb][0], true);
      out[o++] = joint(sides[limb][1], true);
      out[o++] = lastAction()[1 + 2 * limb];
      out[o++] = lastAction()[2 + 2 * limb];
    }
  }
  void computeRewardTerms(double* raw) const override {
    double reach = 0.0;
    for (int h : hands_) reach -= mju_dist3(data_->geom_xpos + 3 * h, data_->xpos + 3 * ball_);
    raw[0] = reach;
    double effort = 0.0;
    for (double a : lastAction()) effort += a * a;
    raw[1] = effort;
  }
  bool isTerminated() const override { return data_->xpos[3 * ball_ + 2] < terminate_below_; }

 private:
  double terminate_below_, noise_;
  int ball_, hands_[2];
};

std::unique_ptr<Task> makeTwinArm(std::shared_ptr<const MujocoModel> m, const sym::SymmetrySpec& s, EnvParams& p) {
  return std::make_unique<TwinArmTask>(std::move(m), s, p);
}

sym::SymmetrySpec twinSpec() { return sym::SymmetrySpec::load(kFrameworkData + "/twin_arm_spec.yaml"); }

std::string specText() { return readTextFile(kFrameworkData + "/twin_arm_spec.yaml"); }

// A test fixture, not in tasks/tasks.cpp's list: added once, before the first factory.
void registerTwinArm() {
  static const bool registered = [] {
    taskCatalog().add({"twin_arm_test", "tests/data/twin_arm.xml", &makeTwinArm});
    return true;
  }();
  (void)registered;
}

TaskFactory factory(const std::string& env_yaml = "{}", const sym::SymmetrySpec& spec = twinSpec()) {
  registerTwinArm();
  return TaskFactory(taskCatalog(), "twin_arm_test", spec, YAML::Load(env_yaml), {}, "test env");
}

TEST(TaskFramework, ResetsAndRuns1000RandomStepsWithFiniteObservationsAndRewards) {
  auto f = factory("{max_episode_steps: 200}");
  auto t = f.create();
  int episodes = 0;
  ASSERT_NO_FATAL_FAILURE(runRandomSteps(*t, 1, 1000, episodes));
  EXPECT_EQ(episodes, 5);  // 1000 steps of 200-step episodes
}

TEST(TaskFramework, RewardIsTheWeightedSumOfItsTerms) {
  auto t = factory("{weights: {reach: 2.0, effort: -0.5}}").create();
  Rng rng(2);
  t->reset(rng);
  const std::vector<float> act{0.5f, -0.2f, 0.1f, 0.3f, 0.0f};
  const StepOutcome o = t->step(act.data());
  ASSERT_EQ(t->rewardTermNames(), (std::vector<std::string>{"reach", "effort", "termination"}));
  const auto& terms = t->rewardTerms();
  EXPECT_NEAR(terms[1], -0.5 * (0.25 + 0.04 + 0.01 + 0.09), 1e-7);  // actions arrive as floats
  EXPECT_LT(terms[0], 0.0);
  EXPECT_EQ(terms[2], 0.0);
  EXPECT_NEAR(o.reward, terms[0] + terms[1], 1e-12);
}

TEST(TaskFramework, TerminationGivesExactlyMinusOneAndTimeoutTruncatesWithoutIt) {
  auto dying = factory("{terminate_below: 10.0}").create();
  Rng rng(3);
  dying->reset(rng);
  const std::vector<float> zero(dying->actDim(), 0.0f);
  const StepOutcome d = dying->step(zero.data());
  EXPECT_TRUE(d.terminated);
  EXPECT_FALSE(d.truncated);
  EXPECT_EQ(d.reward, -1.0);
  EXPECT_EQ(dying->rewardTerms().back(), -1.0);
  EXPECT_TRUE(dying->episode().terminated);

  auto timed = factory("{max_episode_steps: 3}").create();
  timed->reset(rng);
  StepOutcome o;
  for (int s = 0; s < 3; ++s) {
    EXPECT_FALSE(o.truncated);
    o = timed->step(zero.data());
  }
  EXPECT_TRUE(o.truncated);
  EXPECT_FALSE(o.terminated);
  EXPECT_NE(o.reward, -1.0);
  EXPECT_EQ(timed->episode().length, 3);
  EXPECT_NEAR(timed->episode().ret, timed->episode().term_sums[0] + timed->episode().term_sums[1], 1e-12);
}

TEST(TaskFramework, SameSeedGivesBitIdenticalTrajectoriesAndAnotherSeedDoesNot) {
  auto f = factory();
  auto run = [&](std::uint64_t seed) { return recordTrajectory(f, seed, {.steps = 100, .record_reward = false}); };
  EXPECT_EQ(run(7), run(7));
  EXPECT_NE(run(7), run(8));
}

TEST(TaskFramework, ApplyingTheMirrorTwiceRestoresTheState) {
  auto f = factory();
  auto a = f.create(), b = f.create();
  Rng rng(4);
  a->reset(rng);
  b->copyStateFrom(*a);
  b->applySymmetry(1);
  b->applySymmetry(1);
  for (int k = 0; k < a->model()->nq; ++k) EXPECT_NEAR(a->data()->qpos[k], b->data()->qpos[k], 1e-15);
  for (int k = 0; k < a->model()->nv; ++k) EXPECT_NEAR(a->data()->qvel[k], b->data()->qvel[k], 1e-15);
}

// Tolerance 1e-9: one step from mirrored states is the same computation with mirrored numbers,
// so what differs is rounding and the constraint solver's iteration order (contact ordering).
TEST(SymmetryVerifier, PassesOnTheCorrectSpec) {
  const SymmetryReport r = verifySymmetry(factory(), {.num_states = 10, .steps = 3, .tolerance = 1e-9});
  EXPECT_TRUE(r.passed()) << r.summary();
  EXPECT_GT(r.joints.size(), 0u);
}

TEST(SymmetryVerifier, NamesTheEntryWhoseSignIsWrong) {
  std::string text = specText();
  // Claim the elbow flips under the mirror (it does not): observation and action both.
  for (const char* what : {"elbow_pos, kind: invariant", "elbow_vel, kind: invariant", "elbow_action, kind: invariant",
                           "elbow, kind: invariant"}) {
    const auto at = text.find(what);
    ASSERT_NE(at, std::string::npos) << what;
    text.replace(text.find("invariant", at), 9, "odd");
  }
  const auto broken = sym::SymmetrySpec::parseString(text, "broken.yaml");
  const SymmetryReport r = verifySymmetry(factory("{}", broken), {.num_states = 5});
  EXPECT_FALSE(r.passed());
  const NamedError worst = worstEntry(r.joints);
  EXPECT_NE(worst.name.find("elbow"), std::string::npos) << r.summary();
  EXPECT_NE(r.summary().find("elbow"), std::string::npos);
}

// Swapping whole limbs of a mirror maps each joint to its true partner still; swapping two slots
// inside one limb does not.
TEST(SymmetryVerifier, NamesTheJointsWhenActuatorsAreSwappedInsideALimb) {
  std::string text = specText();
  const std::string left = "[left_shoulder, left_elbow]";
  text.replace(text.find(left), left.size(), "[left_elbow, left_shoulder]");
  const auto broken = sym::SymmetrySpec::parseString(text, "swapped.yaml");
  const SymmetryReport r = verifySymmetry(factory("{}", broken), {.num_states = 5});
  EXPECT_FALSE(r.passed());
  // Before any step, the observation map already isolates the arm joints; the waist and the ball
  // (mapped correctly) stay exact.
  for (const NamedError& e : r.observation_map) {
    const bool arm = e.name.find("shoulder") != std::string::npos || e.name.find("elbow") != std::string::npos;
    const bool action = e.name.find("action") != std::string::npos;
    if (!arm) {
      EXPECT_LT(e.error, 1e-9) << e.name;
    } else if (!action && e.name.find("limb1") != std::string::npos) {
      EXPECT_GT(e.error, 1e-3) << e.name;
    }
  }
}

TEST(TaskErrors, UnknownTaskListsTheKnownOnes) {
  registerTwinArm();
  try {
    TaskFactory(taskCatalog(), "no_such_task", twinSpec(), YAML::Load("{}"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("twin_arm_test"), std::string::npos) << e.what();
  }
}

TEST(TaskErrors, MissingModelFileIsNamed) {
  try {
    factory("{model_file: /nonexistent/robot.xml}");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/robot.xml"), std::string::npos) << e.what();
  }
}

TEST(TaskErrors, UnknownEnvParameterNamesTheKey) {
  try {
    factory("{weights: {reech: 1.0}}");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "env.weights.reech");
  }
  try {
    factory("{frame_skip: 0}");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "env.frame_skip");
  }
}

TEST(TaskErrors, WrongActionSizeIsRejected) {
  auto t = factory().create();
  Rng rng(5);
  t->reset(rng);
  const std::vector<float> short_action(t->actDim() - 1, 0.0f);
  EXPECT_THROW(t->step(std::span<const float>(short_action)), std::invalid_argument);
}

TEST(TaskErrors, SpecNamingAMissingActuatorIsNamed) {
  std::string text = specText();
  text.replace(text.find("central: [waist]"), 16, "central: [wiast]");
  try {
    factory("{}", sym::SymmetrySpec::parseString(text, "typo.yaml"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("wiast"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace masa::task
