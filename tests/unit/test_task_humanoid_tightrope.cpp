// Humanoid Tightrope (tasks/humanoid_tightrope): loading, the mirror-symmetric model, the start on
// the rope, reward terms and termination on hand-made states, determinism, and the C2 symmetry of
// spec + model checked against the simulation (including broken specs that must fail).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "task_test_support.hpp"

namespace masa::task {
namespace {

using namespace masa::test;

const std::string kTightropeTask = "humanoid_tightrope";

// The shipped env without reset noise: hand-made states start from the exact start pose.
YAML::Node quietEnv() {
  return editedEnv(kTightropeTask, [](YAML::Node& env) { env["reset_noise"] = 0.0; });
}
TaskFactory quietTightropeFactory() { return envFactory(kTightropeTask, quietEnv()); }

// Lifts the humanoid off the rope (no contact) and gives the root a world velocity.
void floatWithVelocity(Task& t, double vx, double vy) {
  mjData* d = t.data();
  d->qpos[2] += 0.3;
  std::fill(d->qvel, d->qvel + t.model()->nv, 0.0);
  d->qvel[0] = vx;
  d->qvel[1] = vy;
  mj_forward(t.model(), d);
}

TEST(HumanoidTightropeTask, LoadsFromRunConfigAndRuns1000RandomStepsWithFiniteValues) {
  const TaskFactory f = runConfigFactory(kTightropeTask);
  auto t = f.create();
  ASSERT_EQ(t->obsDim(), 74);
  ASSERT_EQ(t->actDim(), 21);
  EXPECT_EQ(t->maxEpisodeSteps(), 1000);
  EXPECT_NEAR(t->controlTimestep(), 0.015, 1e-12);
  int episodes = 0;
  ASSERT_NO_FATAL_FAILURE(runRandomSteps(*t, 1, 1000, episodes, {.contact_buffers = true}));
  EXPECT_GT(episodes, 3);  // random torques make it fall off the rope within a second or so
}

// The left side is the numerical mirror image of the right one, and each left hinge axis is the
// mirrored right axis times the sign the spec declares (odd: -1): the spec and the model agree.
TEST(HumanoidTightropeTask, ModelLeftSideIsTheMirrorOfTheRightWithTheSpecsJointSigns) {
  TaskFactory f = envFactory(kTightropeTask);
  const mjModel* m = f.model()->get();
  const sym::SymmetrySpec spec = shippedSpec(kTightropeTask);
  const auto& right = spec.mujoco().limb_actuators[0];
  const auto& left = spec.mujoco().limb_actuators[1];
  const auto& kinds = spec.actionLayout().limb;
  for (size_t k = 0; k < right.size(); ++k) {
    const int jr = m->actuator_trnid[2 * f.model()->id(mjOBJ_ACTUATOR, right[k])];
    const int jl = m->actuator_trnid[2 * f.model()->id(mjOBJ_ACTUATOR, left[k])];
    const double s = kinds[k].kind == sym::EntryKind::kOdd ? -1.0 : 1.0;
    const double* ar = m->jnt_axis + 3 * jr;
    const double* al = m->jnt_axis + 3 * jl;
    // Hinge axes are axial: the mirror maps a to -M a.
    EXPECT_NEAR(al[0], -s * ar[0], 1e-12) << right[k];
    EXPECT_NEAR(al[1], s * ar[1], 1e-12) << right[k];
    EXPECT_NEAR(al[2], -s * ar[2], 1e-12) << right[k];
    const double* rr = m->jnt_range + 2 * jr;
    const double* rl = m->jnt_range + 2 * jl;
    EXPECT_NEAR(rl[0], s > 0 ? rr[0] : -rr[1], 1e-12) << right[k];
    EXPECT_NEAR(rl[1], s > 0 ? rr[1] : -rr[0], 1e-12) << right[k];
    EXPECT_EQ(m->jnt_stiffness[jl], m->jnt_stiffness[jr]) << right[k];
    EXPECT_EQ(m->dof_damping[m->jnt_dofadr[jl]], m->dof_damping[m->jnt_dofadr[jr]]) << right[k];
    EXPECT_EQ(m->actuator_gear[6 * f.model()->id(mjOBJ_ACTUATOR, left[k])],
              m->actuator_gear[6 * f.model()->id(mjOBJ_ACTUATOR, right[k])]) << right[k];
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(m->jnt_pos[3 * jl + c], (c == 1 ? -1 : 1) * m->jnt_pos[3 * jr + c], 1e-12) << right[k];
  }
  int pairs = 0;
  for (int g = 0; g < m->ngeom; ++g) {
    const std::string name = mj_id2name(m, mjOBJ_GEOM, g);
    if (name.rfind("right_", 0) != 0) continue;
    const int gl = f.model()->id(mjOBJ_GEOM, "left_" + name.substr(6));
    ++pairs;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(m->geom_pos[3 * gl + c], (c == 1 ? -1 : 1) * m->geom_pos[3 * g + c], 1e-12) << name;
      EXPECT_EQ(m->geom_size[3 * gl + c], m->geom_size[3 * g + c]) << name;
    }
    const int br = m->geom_bodyid[g], bl = m->geom_bodyid[gl];
    EXPECT_NEAR(m->body_mass[bl], m->body_mass[br], 1e-12) << name;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(m->body_pos[3 * bl + c], (c == 1 ? -1 : 1) * m->body_pos[3 * br + c], 1e-12) << name;
      EXPECT_NEAR(m->body_ipos[3 * bl + c], (c == 1 ? -1 : 1) * m->body_ipos[3 * br + c], 1e-12) << name;
      EXPECT_NEAR(m->body_inertia[3 * bl + c], m->body_inertia[3 * br + c], 1e-12) << name;
    }
  }
  EXPECT_EQ(pairs, 7);  // thigh, shin, 2 foot capsules, upper arm, lower arm, hand
  const int rope = f.model()->id(mjOBJ_GEOM, "rope");
  EXPECT_EQ(m->geom_pos[3 * rope + 1], 0.0);                                   // on the mirror plane
  EXPECT_NEAR(m->geom_pos[3 * rope + 2] + m->geom_size[3 * rope], 0.85, 1e-12);  // top surface
  EXPECT_NEAR(m->geom_size[3 * rope], 0.05, 1e-12);
}

TEST(HumanoidTightropeTask, ResetStandsUprightWithAFootTouchingTheRopeTop) {
  TaskFactory f = envFactory(kTightropeTask);
  auto t = f.create();
  for (int seed = 0; seed < 5; ++seed) {
    Rng rng(seed);
    t->reset(rng);
    const mjModel* m = t->model();
    const mjData* d = t->data();
    const int rope = mj_name2id(m, mjOBJ_GEOM, "rope");
    int rope_contacts = 0;
    for (int c = 0; c < d->ncon; ++c) {
      EXPECT_GT(d->contact[c].dist, -1e-6) << "no penetration at the start";
      if (d->contact[c].geom1 != rope && d->contact[c].geom2 != rope) continue;
      ++rope_contacts;
      // On the rope's top (within 60 deg of it), not on its flank: axis height 0.8, radius 0.05.
      EXPECT_GT(d->contact[c].pos[2], 0.8 + 0.5 * 0.05) << "seed " << seed;
    }
    EXPECT_GE(rope_contacts, 1) << "seed " << seed;
    const std::vector<float> obs = observation(*t);
    EXPECT_NEAR(obs[obsIndex(*t, "central.torso_z")], 2.125, 0.02);
    EXPECT_NEAR(obs[obsIndex(*t, "central.torso_y")], 0.0, 1e-12);
    EXPECT_NEAR(obs[obsIndex(*t, "central.torso_roll")], 0.0, 1e-12);
    EXPECT_NEAR(obs[obsIndex(*t, "limb0.hip_x_pos")], 0.04, 0.0101);
  }
}

TEST(HumanoidTightropeTask, StandingStillEarnsNoVelocityRewardButTheAliveUpAndHeadingBonus) {
  TaskFactory f = quietTightropeFactory();
  auto t = f.create();
  Rng rng(0);
  t->reset(rng);
  const StepOutcome o = stepZero(*t);
  ASSERT_FALSE(o.terminated);
  EXPECT_LT(std::abs(rewardTerm(*t, "velocity")), 0.01);
  EXPECT_EQ(rewardTerm(*t, "alive"), 2.0);
  EXPECT_EQ(rewardTerm(*t, "up"), 0.1);
  EXPECT_NEAR(rewardTerm(*t, "heading"), 0.1, 1e-4);
  EXPECT_EQ(rewardTerm(*t, "action"), 0.0);  // zero action: no action or energy cost
  EXPECT_EQ(rewardTerm(*t, "energy"), 0.0);
  EXPECT_EQ(rewardTerm(*t, "termination"), 0.0);
  double sum = 0.0;
  for (double v : t->rewardTerms()) sum += v;
  EXPECT_DOUBLE_EQ(o.reward, sum);
}

TEST(HumanoidTightropeTask, VelocityRewardIsForwardSpeedAndLateralPenaltyIsSignless) {
  TaskFactory f = quietTightropeFactory();
  auto t = f.create();
  Rng rng(0);
  for (double vy : {0.3, -0.3}) {
    t->reset(rng);
    floatWithVelocity(*t, 0.8, vy);
    stepZero(*t);
    EXPECT_NEAR(rewardTerm(*t, "velocity"), 0.8, 0.02);  // weight 1.0; joint springs shift the torso a little
    EXPECT_NEAR(rewardTerm(*t, "lateral"), -0.3, 0.02);  // weight -1.0 on |v_y|, whichever side
  }
  t->reset(rng);
  floatWithVelocity(*t, -0.5, 0.0);
  stepZero(*t);
  EXPECT_NEAR(rewardTerm(*t, "velocity"), -0.5, 0.02);  // walking backwards costs
}

TEST(HumanoidTightropeTask, HeadingAndUpFollowTheTorsoAxes) {
  TaskFactory f = quietTightropeFactory();
  auto t = f.create();
  Rng rng(0);
  t->reset(rng);
  floatWithVelocity(*t, 0.0, 0.0);
  double* q = t->data()->qpos + 3;  // root quaternion: yaw 60 deg
  q[0] = std::cos(M_PI / 6);
  q[3] = std::sin(M_PI / 6);
  mj_forward(t->model(), t->data());
  stepZero(*t);
  EXPECT_NEAR(rewardTerm(*t, "heading"), 0.1 * 0.5, 1e-3);
  EXPECT_EQ(rewardTerm(*t, "up"), 0.1);
  t->reset(rng);
  floatWithVelocity(*t, 0.0, 0.0);
  q[0] = std::cos(M_PI / 12);  // roll 30 deg: torso z axis' world z = 0.866 < 0.93
  q[1] = std::sin(M_PI / 12);
  mj_forward(t->model(), t->data());
  stepZero(*t);
  EXPECT_EQ(rewardTerm(*t, "up"), 0.0);
  EXPECT_NEAR(rewardTerm(*t, "heading"), 0.1, 1e-3);
}

TEST(HumanoidTightropeTask, ActionAndEnergyCostsFollowTheAppendix) {
  TaskFactory f = quietTightropeFactory();
  auto t = f.create();
  Rng rng(0);
  t->reset(rng);
  std::vector<float> a(t->actDim());
  for (int k = 0; k < t->actDim(); ++k) a[k] = (k % 2 ? 0.5f : -0.5f);
  a[0] = 3.0f;  // clamped to 1
  t->step(a.data());
  EXPECT_NEAR(rewardTerm(*t, "action"), -0.01 * (1.0 + 20 * 0.25), 1e-12);
  // Energy: -0.05 * 0.1 * sum_k |a_k * qdot_k| * gear_k / max gear over the actuated joints
  // (Task::jointPower: IsaacGymEnvs' Humanoid electricity cost, which the paper's weights were
  // tuned for; the Ant's is 0.2 and unweighted).
  const mjModel* m = t->model();
  double max_gear = 0.0;
  for (int k = 0; k < m->nu; ++k) max_gear = std::max(max_gear, m->actuator_gear[6 * k]);
  double power = 0.0;
  bool unequal_gears = false;
  for (int k = 0; k < m->nu; ++k) {
    const int j = m->actuator_trnid[2 * k];
    const double ratio = m->actuator_gear[6 * k] / max_gear;
    unequal_gears |= ratio < 0.99;
    power += 0.1 * std::abs(t->data()->ctrl[k] * t->data()->qvel[m->jnt_dofadr[j]]) * ratio;
  }
  EXPECT_TRUE(unequal_gears);  // otherwise the weighting would not be tested
  EXPECT_GT(power, 0.0);
  EXPECT_NEAR(rewardTerm(*t, "energy"), -0.05 * power, 1e-12);
}

TEST(HumanoidTightropeTask, TorsoFallingBelowStartMinus075TerminatesWithExactlyMinusOne) {
  TaskFactory f = quietTightropeFactory();
  auto t = f.create();
  Rng rng(0);
  t->reset(rng);
  const double start_z = t->data()->qpos[2];
  // Beside the rope (y = 1), still 0.7 m below the start: alive.
  t->data()->qpos[1] = 1.0;
  t->data()->qpos[2] = start_z - 0.7;
  mj_forward(t->model(), t->data());
  EXPECT_FALSE(stepZero(*t).terminated);
  t->data()->qpos[2] = start_z - 0.8;
  mj_forward(t->model(), t->data());
  const StepOutcome o = stepZero(*t);
  EXPECT_TRUE(o.terminated);
  EXPECT_FALSE(o.truncated);
  EXPECT_EQ(o.reward, -1.0);
  EXPECT_EQ(rewardTerm(*t, "termination"), -1.0);
  EXPECT_EQ(rewardTerm(*t, "alive"), 0.0);
  EXPECT_TRUE(t->episode().terminated);
}

// env.max_tilt_deg (the authors' later version: 30): a torso tilted past it ends the episode with
// the termination reward; the paper's task (0, the default) lets it lean until it falls.
TEST(HumanoidTightropeTask, TiltPastMaxTiltTerminatesOnlyWhenTheOptionIsSet) {
  expectTiltTerminationOnlyWhenSet(kTightropeTask);
}

TEST(HumanoidTightropeTask, TimeLimitTruncatesWithoutPenalty) {
  TaskFactory f = envFactory(kTightropeTask, editedEnv(kTightropeTask, [](YAML::Node& env) { env["max_episode_steps"] = 5; }));
  auto t = f.create();
  Rng rng(0);
  t->reset(rng);
  StepOutcome o;
  ASSERT_NO_FATAL_FAILURE(stepZeroToTimeLimit(*t, 5, o));
  EXPECT_GT(o.reward, 1.5);
  EXPECT_EQ(rewardTerm(*t, "termination"), 0.0);
  EXPECT_EQ(t->episode().length, 5);
  EXPECT_TRUE(t->episode().truncated);
}

TEST(HumanoidTightropeTask, SameSeedIsBitIdenticalAndDifferentSeedDiffers) {
  TaskFactory f = envFactory(kTightropeTask);
  expectSameSeedBitIdenticalOtherSeedDiffers([&](std::uint64_t seed) { return recordTrajectory(f, seed); }, 7, 8);
}

// Tolerance: the mirrored and the original simulations solve the same contact problem with the
// constraint rows in another order; MuJoCo's Newton solver converges to ~1e-12 (measured worst
// 2e-12 over 3 steps), and observations are exact sign flips. A wrong sign or swapped joint
// gives errors of 1e-3 and more within one step, so 1e-8 separates the two by orders of magnitude.
constexpr double kTightropeTolerance = 1e-8;

// The verifier on a few states of the shipped task with `spec` in place of its own.
SymmetryReport verifyTightropeWithSpec(const sym::SymmetrySpec& spec) {
  return verifySymmetry(envFactory(kTightropeTask, shippedEnv(kTightropeTask), spec), {.num_states = 5, .tolerance = kTightropeTolerance});
}

TEST(HumanoidTightropeTask, PhysicsSymmetryVerifierPasses) {
  TaskFactory f = envFactory(kTightropeTask);
  const SymmetryReport r = verifySymmetry(f, {.num_states = 20, .steps = 3, .tolerance = kTightropeTolerance});
  EXPECT_TRUE(r.passed()) << r.summary();
  // The observation map obs(T s) = T obs(s) holds exactly (signs only) on every entry.
  for (const auto& e : r.observation_map) EXPECT_EQ(e.error, 0.0) << e.name;
  std::printf("%s", r.summary(3).c_str());
}

TEST(HumanoidTightropeTask, AnkleXDeclaredInvariantFailsTheVerifierNamingTheAnkles) {
  const sym::SymmetrySpec broken = editedSpec(kTightropeTask, [](YAML::Node& root) {
    for (YAML::Node e : root["action"]["limb"])
      if (e["name"].as<std::string>() == "ankle_x") e["kind"] = "invariant";
  });
  const SymmetryReport r = verifyTightropeWithSpec(broken);
  EXPECT_FALSE(r.passed());
  // The state map now keeps the ankle_x angles while the (odd) observation entries flip: the
  // observation map names exactly the six ankle_x entries.
  for (const auto& e : r.observation_map) {
    if (e.name.find("ankle_x") != std::string::npos) {
      EXPECT_GT(e.error, 1e-3) << e.name;
    } else {
      EXPECT_EQ(e.error, 0.0) << e.name;
    }
  }
  for (const auto& e : r.joints) {
    if (e.name.find("ankle_x") != std::string::npos) {
      EXPECT_GT(e.error, 1e-3) << e.name;
    }
  }
}

// A consistent relabelling (the observation reads the same wrong joint) keeps the observation map
// exact, so the dynamics must catch it; and since the noise-free start pose is mirror-symmetric, a
// right T maps it onto itself, while the broken one moves exactly the swapped hip joints (x and z).
TEST(HumanoidTightropeTask, HipsSwappedInTheActuatorBindingFailTheVerifier) {
  const sym::SymmetrySpec broken = editedSpec(kTightropeTask, [](YAML::Node& root) {
    YAML::Node limb = root["mujoco"]["actuators"]["limbs"][1];
    const std::string x = limb[3].as<std::string>();
    limb[3] = limb[5].as<std::string>();  // left_hip_z where left_hip_x belongs
    limb[5] = x;
  });
  for (const bool is_broken : {false, true}) {
    TaskFactory f = envFactory(kTightropeTask, quietEnv(), is_broken ? broken : shippedSpec(kTightropeTask));
    auto t = f.create();
    Rng rng(0);
    t->reset(rng);
    const std::vector<double> before(t->data()->qpos, t->data()->qpos + t->model()->nq);
    t->applySymmetry(1);
    for (int j = 0; j < t->model()->njnt; ++j) {
      const int a = t->model()->jnt_qposadr[j];
      const std::string name = mj_id2name(t->model(), mjOBJ_JOINT, j);
      const bool moved = std::abs(t->data()->qpos[a] - before[a]) > 1e-3;
      const bool swapped = name.find("hip_x") != std::string::npos || name.find("hip_z") != std::string::npos;
      EXPECT_EQ(moved, is_broken && swapped) << name;
    }
  }
  const SymmetryReport r = verifyTightropeWithSpec(broken);
  EXPECT_FALSE(r.passed());
  for (const auto& e : r.observation_map) EXPECT_EQ(e.error, 0.0) << e.name;
  for (const auto& e : r.joints) {
    if (e.name.find("hip_x") != std::string::npos) {
      EXPECT_GT(e.error, 1e-3) << e.name;
    }
  }
}

TEST(HumanoidTightropeTask, RollDeclaredInvariantFailsTheObservationMapNamingIt) {
  const sym::SymmetrySpec broken = editedSpec(kTightropeTask, [](YAML::Node& root) {
    for (YAML::Node e : root["observation"]["central"])
      if (e["name"].as<std::string>() == "torso_roll") e["kind"] = "invariant";
  });
  const SymmetryReport r = verifyTightropeWithSpec(broken);
  EXPECT_FALSE(r.passed());
  for (const auto& e : r.observation_map) {
    if (e.name == "central.torso_roll") {
      EXPECT_GT(e.error, 1e-4);
    } else {
      EXPECT_EQ(e.error, 0.0) << e.name;
    }
  }
}

}  // namespace
}  // namespace masa::task
