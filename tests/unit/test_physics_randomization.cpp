// Randomized physics (issue #52, item 1; common/sim/physics_randomization.hpp): every key changes
// the model as stated and is reproducible from the seed; symmetric draws keep the spec true (the
// verifier passes) and per-limb draws break it; the latency delays actions by the stated steps;
// a copied or saved task goes on with the same physics; bad ranges are refused naming the key.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/core/config_error.hpp"
#include "common/physics_symmetry/imperfection_report.hpp"
#include "common/sim/episode_pushes.hpp"
#include "task_test_support.hpp"

namespace masa::test {
namespace {

task::TaskFactory randomizedFactory(const std::string& task_name, const std::string& randomization_yaml) {
  YAML::Node env = shippedEnv(task_name);
  env["randomization"] = YAML::Load(randomization_yaml);
  return task::TaskFactory(task::taskCatalog(), task_name, shippedSpec(task_name), env);
}

std::vector<double> masses(const task::Task& t) {
  return std::vector<double>(t.model()->body_mass, t.model()->body_mass + t.model()->nbody);
}

TEST(PhysicsRandomization, WithoutTheSectionTheTaskSharesTheNominalModel) {
  task::TaskFactory f(task::taskCatalog(), "a1_beam", shippedSpec("a1_beam"), shippedEnv("a1_beam"));
  const auto t = f.create();
  EXPECT_EQ(t->randomization(), nullptr);
  EXPECT_EQ(t->model(), f.model()->get()) << "a task without randomization copied its model";
}

TEST(PhysicsRandomization, EachScaleChangesTheModelWithinItsRangeReproduciblyFromTheSeed) {
  const auto f = randomizedFactory("a1_beam", "{mass_scale: [0.8, 1.2], geom_friction_scale: [0.5, 1.5], "
                                              "joint_damping_scale: [0.5, 2.0], joint_friction_scale: [0.5, 2.0], "
                                              "actuator_strength: [0.8, 0.9]}");
  const auto a = f.create(), b = f.create(), c = f.create();
  const mjModel* nominal = f.model()->get();
  Rng ra(5), rb(5), rc(6);
  a->reset(ra);
  b->reset(rb);
  c->reset(rc);
  const mjModel* m = a->model();
  ASSERT_NE(m, nominal) << "a randomized task writes the factory's shared model";
  bool mass_moved = false;
  for (int i = 1; i < m->nbody; ++i) {
    if (nominal->body_mass[i] == 0.0) continue;
    const double s = m->body_mass[i] / nominal->body_mass[i];
    EXPECT_GE(s, 0.8 - 1e-12);
    EXPECT_LE(s, 1.2 + 1e-12);
    EXPECT_NEAR(m->body_inertia[3 * i] / nominal->body_inertia[3 * i], s, 1e-9) << "inertia scales with the mass";
    mass_moved = mass_moved || std::abs(s - 1.0) > 1e-6;
  }
  EXPECT_TRUE(mass_moved);
  for (int g = 0; g < m->ngeom; ++g) {
    const double s = m->geom_friction[3 * g] / nominal->geom_friction[3 * g];
    EXPECT_GE(s, 0.5 - 1e-12);
    EXPECT_LE(s, 1.5 + 1e-12);
  }
  for (int u = 0; u < m->nu; ++u) {
    const double s = m->actuator_gear[6 * u] / nominal->actuator_gear[6 * u];
    EXPECT_GE(s, 0.8 - 1e-12);
    EXPECT_LE(s, 0.9 + 1e-12);
  }
  for (int v = 0; v < m->nv; ++v)
    if (nominal->dof_damping[v] > 0.0) {
      EXPECT_GE(m->dof_damping[v] / nominal->dof_damping[v], 0.5 - 1e-12);
    }
  EXPECT_EQ(masses(*a), masses(*b)) << "the same seed drew other physics";
  EXPECT_NE(masses(*a), masses(*c)) << "another seed drew the same physics";
  // A new episode draws anew, from the nominal model (scales do not compound).
  a->reset(ra);
  for (int i = 1; i < m->nbody; ++i)
    if (nominal->body_mass[i] > 0.0) {
      EXPECT_LE(m->body_mass[i] / nominal->body_mass[i], 1.2 + 1e-12);
    }
}

TEST(PhysicsRandomization, SymmetricDrawsKeepTheSpecTrueAndPerLimbDrawsBreakIt) {
  const std::string scales = "mass_scale: [0.7, 1.3], geom_friction_scale: [0.6, 1.4], joint_damping_scale: [0.5, 2.0], "
                             "actuator_strength: [0.8, 1.2], pd_kp_scale: [0.7, 1.3], pd_kd_scale: [0.7, 1.3], com_offset: 0.01";
  for (const std::string task_name : {"a1_beam", "trifinger_lift"}) {
    const auto symmetric = randomizedFactory(task_name, "{" + scales + "}");
    const task::SymmetryReport ok = task::verifySymmetry(symmetric, {.num_states = 4, .diagnosis_states = 0});
    EXPECT_TRUE(ok.passed()) << task_name << ": the symmetric randomization broke the symmetry:\n" << ok.summary();
    const auto per_limb = randomizedFactory(task_name, "{per_limb: true, " + scales + "}");
    const task::SymmetryReport broken = task::verifySymmetry(per_limb, {.num_states = 4, .diagnosis_states = 0});
    EXPECT_FALSE(broken.passed()) << task_name << ": per-limb draws left the robot symmetric";
  }
}

// Centre-of-mass offsets mapped with the symmetry keep it (the reflection of A1 Beam, the rotations
// of TriFinger and the C4 walker); drawn per limb they break it. Read back: every offset within the
// bound, the A1's trunk moved only within the mirror plane (its y offset stays 0).
TEST(PhysicsRandomization, SymmetricComOffsetsKeepTheSpecTrueAndPerLimbOnesBreakIt) {
  for (const std::string task_name : {"a1_beam", "trifinger_lift", "c4_walker"}) {
    const auto symmetric = randomizedFactory(task_name, "{com_offset: 0.02}");
    const task::SymmetryReport ok = task::verifySymmetry(symmetric, {.num_states = 4, .diagnosis_states = 0});
    EXPECT_TRUE(ok.passed()) << task_name << ": symmetric centre-of-mass offsets broke the symmetry:\n" << ok.summary();
    const auto per_limb = randomizedFactory(task_name, "{per_limb: true, com_offset: 0.02}");
    const task::SymmetryReport broken = task::verifySymmetry(per_limb, {.num_states = 4, .diagnosis_states = 0});
    EXPECT_FALSE(broken.passed()) << task_name << ": per-limb offsets left the robot symmetric";
  }
  const auto f = randomizedFactory("a1_beam", "{com_offset: 0.02}");
  const auto a = f.create(), b = f.create();
  Rng ra(8), rb(8);
  a->reset(ra);
  b->reset(rb);
  const mjModel* m = a->model();
  const mjModel* nominal = f.model()->get();
  int moved = 0;
  for (int i = 0; i < 3 * m->nbody; ++i) {
    const double d = m->body_ipos[i] - nominal->body_ipos[i];
    EXPECT_LE(std::abs(d), 0.02 * std::sqrt(3.0) + 1e-12);
    EXPECT_EQ(m->body_ipos[i], b->model()->body_ipos[i]) << "the same seed drew another offset";
    moved += std::abs(d) > 1e-6 ? 1 : 0;
  }
  EXPECT_GT(moved, 6);
  const int trunk = mj_name2id(m, mjOBJ_BODY, "trunk");
  ASSERT_GE(trunk, 0);
  EXPECT_NEAR(m->body_ipos[3 * trunk + 1], nominal->body_ipos[3 * trunk + 1], 1e-12) << "the trunk moved off the mirror plane";
  EXPECT_GT(std::abs(m->body_ipos[3 * trunk] - nominal->body_ipos[3 * trunk]), 1e-6) << "the trunk got no offset";
}

TEST(PhysicsRandomization, TheLatencyDelaysAnActionByTheStatedSteps) {
  for (int latency : {0, 1, 3}) {
    const auto f = randomizedFactory("ant_acrobatic", "{latency_steps: " + std::to_string(latency) + "}");
    const auto t = f.create();
    Rng rng(1);
    t->reset(rng);
    const int A = t->actDim();
    const std::vector<float> push(A, 0.7f), rest(A, 0.0f);
    std::vector<double> first_ctrl;
    for (int step = 0; step <= latency + 1; ++step) {
      t->step(step == 0 ? push.data() : rest.data());
      const double ctrl = t->data()->ctrl[t->actuatorOfAction(0)];
      // The pushed action acts at step `latency` alone: before, the zeros of the start; after, rest.
      if (step == latency) {
        EXPECT_GT(std::abs(ctrl), 1e-9) << "latency " << latency << ": not applied at step " << step;
      } else {
        EXPECT_NEAR(ctrl, 0.0, 1e-12) << "latency " << latency << ": step " << step;
      }
    }
    EXPECT_EQ(t->lastAction()[0], 0.0) << "the observation's last action is the commanded one";
  }
}

TEST(PhysicsRandomization, ACopiedTaskGoesOnWithTheSamePhysicsNoiseAndDelayedActions) {
  const auto f = randomizedFactory("a1_beam", "{mass_scale: [0.8, 1.2], latency_steps: [1, 2], obs_noise_std: 0.01, "
                                              "obs_bias: 0.02}");
  const auto a = f.create(), b = f.create();
  Rng ra(3), rb(4);
  a->reset(ra);
  b->reset(rb);
  std::vector<float> act(a->actDim(), 0.3f);
  for (int k = 0; k < 5; ++k) a->step(act.data());
  b->copyStateFrom(*a);
  EXPECT_EQ(masses(*a), masses(*b));
  std::vector<float> oa(a->obsDim()), ob(b->obsDim());
  for (int k = 0; k < 5; ++k) {
    act.assign(act.size(), 0.1f * k - 0.2f);
    a->step(act.data());
    b->step(act.data());
    a->observe(oa.data());
    b->observe(ob.data());
    ASSERT_EQ(oa, ob) << "step " << k << " after the copy";
  }
  // The noise is there: a noiseless copy of the same state observes otherwise.
  const auto plain = task::TaskFactory(task::taskCatalog(), "a1_beam", shippedSpec("a1_beam"), shippedEnv("a1_beam")).create();
  std::vector<double> state;
  a->saveState(state);
  std::vector<float> clean(a->obsDim());
  ASSERT_THROW(plain->loadState(state), std::runtime_error) << "a randomized state loaded into a task without randomization";
}

TEST(PhysicsRandomization, BadRangesAreRefusedNamingTheKey) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"{mass_scale: [1.2, 0.8]}", "env.randomization.mass_scale"},
      {"{geom_friction_scale: [-1, 2]}", "env.randomization.geom_friction_scale"},
      {"{actuator_strength: [.nan, 1]}", "env.randomization.actuator_strength"},
      {"{joint_damping_scale: [1, 2, 3]}", "env.randomization.joint_damping_scale"},
      {"{latency_steps: [-1, 2]}", "env.randomization.latency_steps"},
      {"{obs_noise_std: -0.1}", "env.randomization.obs_noise_std"},
      {"{mass_scael: [0.9, 1.1]}", "env.randomization.mass_scael"},
      {"{pd_kp_scale: [-0.5, 1]}", "env.randomization.pd_kp_scale"},
      {"{pd_kd_scale: [1.5, 1.2]}", "env.randomization.pd_kd_scale"},
      {"{push_velocity: -1, push_interval_s: 2}", "env.randomization.push_velocity"},
      {"{push_velocity: .nan, push_interval_s: 2}", "env.randomization.push_velocity"},
      {"{push_velocity: 0.5}", "env.randomization.push_interval_s"},
      {"{push_velocity: 0.5, push_interval_s: -3}", "env.randomization.push_interval_s"},
      {"{com_offset: -0.01}", "env.randomization.com_offset"},
      {"{com_offset: .inf}", "env.randomization.com_offset"},
  };
  for (const auto& [yaml, key] : cases) {
    try {
      randomizedFactory("a1_beam", yaml).create();
      ADD_FAILURE() << yaml << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << yaml << ": " << e.what();
    }
  }
}

// The PD loops of A1 Beam, TriFinger and a YAML task multiply their gains by the episode's scales:
// two tasks reset alike (the same draws consumed) with gains at 0.02 and 0.01 command torques 2:1
// (gains this low keep the torques below the motors' limits, where they would be clipped).
TEST(PhysicsRandomization, PdGainScalesScaleTheTasksOwnPdLoop) {
  for (const std::string name : {"a1_beam", "trifinger_lift", "a1_beam_yaml"}) {
    const auto fa = runConfigFactory(name, {"env.randomization={pd_kp_scale: 0.02, pd_kd_scale: 0.02}"});
    const auto fb = runConfigFactory(name, {"env.randomization={pd_kp_scale: 0.01, pd_kd_scale: 0.01}"});
    const auto a = fa.create(), b = fb.create();
    Rng ra(2), rb(2);
    a->reset(ra);
    b->reset(rb);
    const std::vector<float> action(a->actDim(), 0.2f);
    a->actuate(action.data());
    b->actuate(action.data());
    bool moved = false;
    for (int k = 0; k < a->actDim(); ++k) {
      const double ta = a->data()->ctrl[a->actuatorOfAction(k)], tb = b->data()->ctrl[b->actuatorOfAction(k)];
      EXPECT_NEAR(ta, 2.0 * tb, 1e-9 * (1.0 + std::abs(ta))) << name << " action " << k;
      moved = moved || std::abs(ta) > 1e-6;
    }
    EXPECT_TRUE(moved) << name << ": no torque to compare";
    ASSERT_EQ(a->episode().physics.size(), task::PhysicsRandomization::drawNames().size());
    EXPECT_EQ(a->episode().physics[5], 0.02) << name << ": pd_kp_scale in the episode's statistics";
    EXPECT_EQ(b->episode().physics[6], 0.01) << name << ": pd_kd_scale in the episode's statistics";
  }
}

// A push changes the base's horizontal velocity by at most push_velocity and nothing else; the
// same seed pushes alike; a task without a robot base refuses pushes naming the key.
TEST(PhysicsRandomization, PushesChangeTheBaseVelocityReproduciblyFromTheSeed) {
  const auto pushed = randomizedFactory("a1_beam", "{push_velocity: 1.0, push_interval_s: 0.02}");  // every step
  const auto still = randomizedFactory("a1_beam", "{mass_scale: 1.0}");
  const auto p = pushed.create(), q = pushed.create(), s = still.create();
  Rng rp(9), rq(9), rs(9);
  p->reset(rp);
  q->reset(rq);
  s->reset(rs);
  const std::vector<float> action(p->actDim(), 0.0f);
  p->step(action.data());
  q->step(action.data());
  s->step(action.data());
  const mjModel* m = p->model();
  const int trunk = mj_name2id(m, mjOBJ_JOINT, "trunk");  // the robot-base free joint
  ASSERT_GE(trunk, 0);
  const int base = m->jnt_dofadr[trunk];
  const double dvx = p->data()->qvel[base] - s->data()->qvel[base], dvy = p->data()->qvel[base + 1] - s->data()->qvel[base + 1];
  EXPECT_GT(std::hypot(dvx, dvy), 0.0) << "no push at a step with probability 1";
  EXPECT_LE(std::hypot(dvx, dvy), 1.0 + 1e-12);
  for (int v = 0; v < m->nv; ++v) {
    if (v == base || v == base + 1) continue;
    EXPECT_EQ(p->data()->qvel[v], s->data()->qvel[v]) << "dof " << v << " moved by a push";
  }
  for (int v = 0; v < m->nv; ++v) EXPECT_EQ(p->data()->qvel[v], q->data()->qvel[v]) << "the same seed pushed otherwise";
  try {
    randomizedFactory("trifinger_lift", "{push_velocity: 0.5, push_interval_s: 2}").create();
    ADD_FAILURE() << "pushes taken by a task without a robot base";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "env.randomization.push_velocity") << e.what();
  }
}

// Symmetric in distribution: over many steps the pushes come at the stated mean interval, with no
// preferred direction (mean change 0, equal spread along x and y).
TEST(PhysicsRandomization, PushesComeAtTheMeanIntervalInNoPreferredDirection) {
  int pushes = 0;
  double sx = 0, sy = 0, sxx = 0, syy = 0;
  const int steps = 200000;
  for (int k = 0; k < steps; ++k) {
    task::Push push;
    if (!task::pushAtStep(1.0, 0.2, 0.02, 12345, k, &push)) continue;
    ++pushes;
    sx += push.dvx, sy += push.dvy, sxx += push.dvx * push.dvx, syy += push.dvy * push.dvy;
  }
  EXPECT_NEAR(pushes / static_cast<double>(steps), 0.1, 0.005);
  EXPECT_NEAR(sx / pushes, 0.0, 0.01);
  EXPECT_NEAR(sy / pushes, 0.0, 0.01);
  EXPECT_NEAR(sxx / pushes, syy / pushes, 0.01);
  EXPECT_NEAR((sxx + syy) / pushes, 1.0 / 3.0, 0.01);  // E|dv|^2 for a size uniform in [0, 1]
}

// masa_verify --imperfection on a randomized task measures the drawn model: per-limb mass draws
// are named limb by limb; symmetric ones leave no limb apart.
TEST(PhysicsRandomization, TheImperfectionReportNamesTheLimbsOfPerLimbDraws) {
  // The largest relative mass difference of each limb (the nominal A1's own, if any, as the base line).
  auto massGaps = [](const task::ImperfectionReport& r) {
    std::map<int, double> gap;
    for (const task::Imperfection& e : r.entries)
      if (e.term == "mass") gap[e.limb] = std::max(gap[e.limb], e.relative);
    return gap;
  };
  const task::TaskFactory nominal(task::taskCatalog(), "a1_beam", shippedSpec("a1_beam"), shippedEnv("a1_beam"));
  auto base = massGaps(task::imperfectionReport(nominal, {.num_states = 2}));
  const task::ImperfectionReport r =
      task::imperfectionReport(randomizedFactory("a1_beam", "{per_limb: true, mass_scale: [0.7, 1.3]}"), {.num_states = 2});
  int apart = 0;
  for (const auto& [limb, gap] : massGaps(r)) apart += gap > base[limb] + 1e-3 ? 1 : 0;
  EXPECT_GE(apart, 2) << r.summary();
  EXPECT_NE(r.summary().find(": mass"), std::string::npos) << r.summary();
  const task::ImperfectionReport s =
      task::imperfectionReport(randomizedFactory("a1_beam", "{mass_scale: [0.7, 1.3]}"), {.num_states = 2});
  for (const auto& [limb, gap] : massGaps(s)) EXPECT_NEAR(gap, base[limb], 1e-9) << "limb " << limb << "\n" << s.summary();
}

// The draws are in the episode's statistics: each kind's mean drawn scale within its range.
TEST(PhysicsRandomization, TheDrawsAreInTheEpisodeStatistics) {
  const auto f = randomizedFactory("a1_beam", "{mass_scale: [0.8, 1.2], actuator_strength: 0.9, latency_steps: [1, 2]}");
  const auto t = f.create();
  EXPECT_EQ(t->physicsDrawNames(), task::PhysicsRandomization::drawNames());
  Rng rng(4);
  t->reset(rng);
  const std::vector<double>& d = t->episode().physics;
  ASSERT_EQ(d.size(), t->physicsDrawNames().size());
  EXPECT_EQ(t->physicsDrawNames()[0], "physics: mass_scale");
  EXPECT_GE(d[0], 0.8);
  EXPECT_LE(d[0], 1.2);
  EXPECT_NE(d[0], 1.0);
  EXPECT_EQ(d[1], 1.0) << "friction not drawn";
  EXPECT_EQ(d[4], 0.9);
  EXPECT_GE(d[7], 1.0);
  EXPECT_LE(d[7], 2.0);
  const auto plain = task::TaskFactory(task::taskCatalog(), "a1_beam", shippedSpec("a1_beam"), shippedEnv("a1_beam")).create();
  EXPECT_TRUE(plain->physicsDrawNames().empty());
  Rng r2(4);
  plain->reset(r2);
  EXPECT_TRUE(plain->episode().physics.empty());
}

}  // namespace
}  // namespace masa::test
