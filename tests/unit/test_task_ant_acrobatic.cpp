// Ant Acrobatic (tasks/ant_acrobatic): loading, reward terms and termination on hand-made states,
// determinism, and the C4 symmetry of spec + model checked against the simulation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "task_test_support.hpp"

namespace masa::task {
namespace {

using namespace masa::test;

const std::string kAntTask = "ant_acrobatic";

TEST(AntAcrobaticTask, LoadsAndRuns1000RandomStepsWithFiniteValues) {
  TaskFactory f = envFactory(kAntTask);
  auto t = f.create();
  ASSERT_EQ(t->obsDim(), 58);
  ASSERT_EQ(t->actDim(), 8);
  int episodes = 0;
  ASSERT_NO_FATAL_FAILURE(runRandomSteps(*t, 1, 1000, episodes));
  EXPECT_GT(episodes, 0);  // random torques topple the pole
}

TEST(AntAcrobaticTask, ResetPutsAntOnBallWithUprightPoleAndCanonicalQuaternion) {
  TaskFactory f = envFactory(kAntTask);
  auto t = f.create();
  Rng rng(3);
  t->reset(rng);
  const std::vector<float> obs = observation(*t);
  EXPECT_NEAR(obs[obsIndex(*t, "central.pole_up[2]")], 1.0, 1e-9);
  EXPECT_GE(obs[obsIndex(*t, "central.torso_quat_w")], 0.0f);
  EXPECT_NEAR(obs[obsIndex(*t, "central.torso_pos[2]")] - obs[obsIndex(*t, "central.ball_pos[2]")], 1.41, 1e-6);
  for (int leg = 0; leg < 4; ++leg) {
    const double ankle = obs[obsIndex(*t, "limb" + std::to_string(leg) + ".ankle_pos")];
    EXPECT_NEAR(ankle, 80.0 * M_PI / 180.0, 0.1 + 1e-6) << "leg " << leg;
  }
}

// Leg k must be leg 0 rotated by +90k deg about z, exactly: body offsets and joint axes.
TEST(AntAcrobaticTask, ModelLegsAreExactRotationsOfLegZero) {
  TaskFactory f = envFactory(kAntTask);
  const mjModel* m = f.model()->get();
  auto rot = [](const double* v, int k, double* out) {  // +90k deg about z
    double x = v[0], y = v[1];
    for (int r = 0; r < k; ++r) {
      const double nx = -y;
      y = x;
      x = nx;
    }
    out[0] = x;
    out[1] = y;
    out[2] = v[2];
  };
  for (const char* part : {"upper_", "lower_"}) {
    const int b0 = mj_name2id(m, mjOBJ_BODY, (std::string(part) + "0").c_str());
    for (int k = 1; k < 4; ++k) {
      const int bk = mj_name2id(m, mjOBJ_BODY, (part + std::to_string(k)).c_str());
      double want[3];
      rot(m->body_pos + 3 * b0, k, want);
      for (int c = 0; c < 3; ++c) EXPECT_EQ(m->body_pos[3 * bk + c], want[c]) << part << k;
      EXPECT_NEAR(m->body_mass[bk], m->body_mass[b0], 1e-15);
    }
  }
  for (const char* joint : {"hip_", "ankle_"}) {
    const int j0 = mj_name2id(m, mjOBJ_JOINT, (std::string(joint) + "0").c_str());
    for (int k = 1; k < 4; ++k) {
      const int jk = mj_name2id(m, mjOBJ_JOINT, (joint + std::to_string(k)).c_str());
      double want[3];
      rot(m->jnt_axis + 3 * j0, k, want);
      for (int c = 0; c < 3; ++c) EXPECT_EQ(m->jnt_axis[3 * jk + c], want[c]) << joint << k;
      EXPECT_EQ(m->jnt_range[2 * jk], m->jnt_range[2 * j0]);
      EXPECT_EQ(m->jnt_range[2 * jk + 1], m->jnt_range[2 * j0 + 1]);
    }
  }
}

TEST(AntAcrobaticTask, ZeroActionEarnsExactlyTheAliveBonus) {
  TaskFactory f = envFactory(kAntTask);
  auto t = f.create();
  Rng rng(4);
  t->reset(rng);
  const StepOutcome o = stepZero(*t);
  ASSERT_FALSE(o.terminated);
  EXPECT_EQ(o.reward, 0.5);  // zero torque: no action cost and no power
  EXPECT_EQ(t->rewardTerms()[1], 0.0);
  EXPECT_EQ(t->rewardTerms()[2], 0.0);
}

TEST(AntAcrobaticTask, ActionAndEnergyCostsFollowTheAppendix) {
  TaskFactory f = envFactory(kAntTask);
  auto t = f.create();
  Rng rng(5);
  t->reset(rng);
  std::vector<float> act(t->actDim());
  for (int k = 0; k < t->actDim(); ++k) act[k] = (k % 2 ? 0.5f : -1.0f);
  const StepOutcome o = t->step(act.data());
  ASSERT_FALSE(o.terminated);
  const auto& names = t->rewardTermNames();
  ASSERT_EQ(names, (std::vector<std::string>{"alive", "action", "energy", "termination"}));
  const double a2 = 4 * (1.0 + 0.25);
  EXPECT_DOUBLE_EQ(t->rewardTerms()[0], 0.5);
  EXPECT_DOUBLE_EQ(t->rewardTerms()[1], -0.005 * a2);
  // Energy (the paper's weights assume IsaacGym's electricity cost): sum over joints of
  // |action * joint velocity| * 0.2, with the joint velocity of the state the step ended in.
  const mjModel* m = t->model();
  double power = 0.0;
  for (int k = 0; k < 8; ++k) {
    const int dof = m->jnt_dofadr[m->actuator_trnid[2 * k]];
    EXPECT_DOUBLE_EQ(t->data()->qfrc_actuator[dof], 15.0 * act[k]);
    power += 0.2 * std::abs(static_cast<double>(act[k]) * t->data()->qvel[dof]);
  }
  EXPECT_GT(power, 0.0);
  EXPECT_NEAR(t->rewardTerms()[2], -0.05 * power, 1e-9 * power);
  EXPECT_NEAR(o.reward, 0.5 - 0.005 * a2 - 0.05 * power, 1e-9 * (1 + power));
}

TEST(AntAcrobaticTask, TiltedPoleTerminatesWithMinusOne) {
  TaskFactory f = envFactory(kAntTask);
  auto t = f.create();
  Rng rng(6);
  t->reset(rng);
  double* q = jointQpos(*t, "pole_root");
  const double half = 0.5 * 15.0 * M_PI / 180.0;  // 15 deg about x: up_z = 0.966 < 0.98
  q[3] = std::cos(half);
  q[4] = std::sin(half);
  q[5] = q[6] = 0.0;
  const StepOutcome o = stepZero(*t);
  EXPECT_TRUE(o.terminated);
  EXPECT_FALSE(o.truncated);
  EXPECT_EQ(o.reward, -1.0);
  EXPECT_EQ(t->rewardTerms().back(), -1.0);
  EXPECT_TRUE(t->episode().terminated);
}

TEST(AntAcrobaticTask, UprightPoleOutOfTheCupTerminates) {
  TaskFactory f = envFactory(kAntTask);
  auto t = f.create();
  Rng rng(7);
  t->reset(rng);
  double* q = jointQpos(*t, "pole_root");
  q[0] = 3.0;  // standing upright on the floor beside the ball
  q[2] = 1.0;
  const StepOutcome o = stepZero(*t);
  const std::vector<float> obs = observation(*t);
  EXPECT_GT(obs[obsIndex(*t, "central.pole_up[2]")], 0.98);  // not the tilt: the drop ends it
  EXPECT_TRUE(o.terminated);
  EXPECT_EQ(o.reward, -1.0);
}

TEST(AntAcrobaticTask, AntOffTheBallTerminates) {
  TaskFactory f = envFactory(kAntTask);
  auto t = f.create();
  Rng rng(8);
  t->reset(rng);
  jointQpos(*t, "ball_root")[0] = 4.0;  // the ball rolls away from under the level ant
  jointQpos(*t, "ball_root")[2] = 2.0;  // ... and sits level with the torso (0.41 m apart in z)
  const StepOutcome o = stepZero(*t);
  EXPECT_TRUE(o.terminated);
  EXPECT_EQ(o.reward, -1.0);
}

TEST(AntAcrobaticTask, TimeLimitTruncatesWithoutPenalty) {
  TaskFactory f = envFactory(kAntTask, editedEnv(kAntTask, [](YAML::Node& env) { env["max_episode_steps"] = 5; }));
  auto t = f.create();
  Rng rng(9);
  t->reset(rng);
  const std::vector<float> zero(t->actDim(), 0.0f);
  for (int s = 1; s <= 5; ++s) {
    const StepOutcome o = t->step(zero.data());
    ASSERT_FALSE(o.terminated) << "step " << s;
    EXPECT_EQ(o.truncated, s == 5);
    EXPECT_EQ(o.reward, 0.5);
  }
  EXPECT_EQ(t->episode().length, 5);
  EXPECT_DOUBLE_EQ(t->episode().ret, 2.5);
}

TEST(AntAcrobaticTask, SameSeedIsBitIdenticalAndDifferentSeedDiffers) {
  const TrajectoryOptions opt{.steps = 100};
  expectSameSeedBitIdenticalOtherSeedDiffers(
      [&](std::uint64_t seed) { return recordTrajectory(envFactory(kAntTask), seed, opt); }, 11, 12);
}

// Tolerance: a 90 deg rotation maps the model onto itself exactly (exact leg coordinates, elliptic
// friction cones) and the T_i are exact signed permutations, so the two simulations differ only by
// rounding (the conjugated torso quaternion, rotated contact frames, the iterative solver): we see
// ~1e-13 over 1-20 steps. The observations are float32 (values up to ~4 m, 1 ulp ~ 5e-7), so 1e-6
// is the tightest bound that does not depend on a rounding difference crossing a float boundary;
// a wrong sign or a swapped leg gives errors of order 0.1-10.
constexpr double kSymmetryTolerance = 1e-6;

// The verifier on three states of the shipped task with `spec` in place of its own (a broken one).
SymmetryReport verifyWithSpec(const sym::SymmetrySpec& spec, std::uint64_t seed) {
  return verifySymmetry(envFactory(kAntTask, shippedEnv(kAntTask), spec),
                        {.num_states = 3, .max_warmup_steps = 10, .seed = seed, .tolerance = kSymmetryTolerance});
}

TEST(AntAcrobaticTask, PhysicsSymmetryVerifierPasses) {
  TaskFactory f = envFactory(kAntTask);
  const SymmetryReport r = verifySymmetry(
      f, {.num_states = 12, .max_warmup_steps = 40, .steps = 2, .seed = 21, .tolerance = kSymmetryTolerance});
  std::printf("%s", r.summary(4).c_str());
  EXPECT_TRUE(r.passed()) << r.summary(8);
  EXPECT_EQ(r.termination_mismatches, 0);
  // obs(T s) = T obs(s) for every dimension, separately from the dynamics.
  for (const NamedError& e : r.observation_map) EXPECT_LE(e.error, kSymmetryTolerance) << e.name;
}

// The classic ant's alternating ankle signs applied to our rotated axes: the ankles of legs 1 and 2
// are then mapped with the wrong sign (into -100..-30 deg, outside their range) and the verifier
// must name the ankle joints. The observation map alone cannot see this: the same wrong sign is
// applied to the state and to the observation.
TEST(AntAcrobaticTask, WrongAnkleSignsFailTheVerifierNamingTheAnkles) {
  const sym::SymmetrySpec broken = editedSpec(kAntTask, [](YAML::Node& root) {
    for (const char* block : {"observation", "action"})
      for (YAML::Node e : root[block]["limb"])
        if (e["name"].as<std::string>().rfind("ankle", 0) == 0) e["limb_signs"] = std::vector<int>{1, -1, -1, 1};
  });
  const SymmetryReport r = verifyWithSpec(broken, 22);
  EXPECT_FALSE(r.passed());
  const double worst_ankle = worstError(r.joints, [](const std::string& n) { return n.rfind("ankle_", 0) == 0; });
  const double worst_hip = worstError(r.joints, [](const std::string& n) { return n.rfind("hip_", 0) == 0; });
  EXPECT_GT(worst_ankle, 0.1) << r.summary(8);  // pushed back from -80 deg towards +30 deg
  EXPECT_GT(worst_ankle, worst_hip) << r.summary(8);
}

// Swapping two legs in mujoco.actuators breaks the rotation: the hips are named.
TEST(AntAcrobaticTask, SwappedLegBindingFailsTheVerifier) {
  const sym::SymmetrySpec broken = editedSpec(kAntTask, [](YAML::Node& root) {
    YAML::Node limbs = root["mujoco"]["actuators"]["limbs"];
    const YAML::Node l1 = YAML::Clone(limbs[1]);
    limbs[1] = YAML::Clone(limbs[3]);
    limbs[3] = l1;
  });
  const SymmetryReport r = verifyWithSpec(broken, 23);
  EXPECT_FALSE(r.passed());
  const double worst_root = worstError(r.joints, [](const std::string& n) { return n == "root"; });
  EXPECT_GT(worst_root, 1e-3) << r.summary(8);  // mirrored legs push the torso the wrong way
}

// A vector declared invariant: the observation map itself must fail, on the rotated components.
TEST(AntAcrobaticTask, PoleUpDeclaredInvariantFailsTheObservationMap) {
  const sym::SymmetrySpec broken = editedSpec(kAntTask, [](YAML::Node& root) {
    for (YAML::Node e : root["observation"]["central"])
      if (e["name"].as<std::string>() == "pole_up") {
        e["kind"] = "invariant";
        e["count"] = 3;
      }
  });
  const SymmetryReport r = verifyWithSpec(broken, 24);
  EXPECT_FALSE(r.passed());
  for (const NamedError& e : r.observation_map) {
    if (e.name == "central.pole_up[0]" || e.name == "central.pole_up[1]")
      EXPECT_GT(e.error, 1e-4) << e.name;  // the pole tilts a little after random steps
    else
      EXPECT_LE(e.error, kSymmetryTolerance) << e.name;
  }
}

}  // namespace
}  // namespace masa::task
