// Randomized physics (issue #52, item 1; common/sim/physics_randomization.hpp): every key changes
// the model as stated and is reproducible from the seed; symmetric draws keep the spec true (the
// verifier passes) and per-limb draws break it; the latency delays actions by the stated steps;
// a copied or saved task goes on with the same physics; bad ranges are refused naming the key.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/core/config_error.hpp"
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
                             "actuator_strength: [0.8, 1.2]";
  for (const std::string task_name : {"a1_beam", "trifinger_lift"}) {
    const auto symmetric = randomizedFactory(task_name, "{" + scales + "}");
    const task::SymmetryReport ok = task::verifySymmetry(symmetric, {.num_states = 4, .diagnosis_states = 0});
    EXPECT_TRUE(ok.passed()) << task_name << ": the symmetric randomization broke the symmetry:\n" << ok.summary();
    const auto per_limb = randomizedFactory(task_name, "{per_limb: true, " + scales + "}");
    const task::SymmetryReport broken = task::verifySymmetry(per_limb, {.num_states = 4, .diagnosis_states = 0});
    EXPECT_FALSE(broken.passed()) << task_name << ": per-limb draws left the robot symmetric";
  }
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
  };
  for (const auto& [yaml, key] : cases) {
    try {
      randomizedFactory("a1_beam", yaml);
      ADD_FAILURE() << yaml << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << yaml << ": " << e.what();
    }
  }
}

}  // namespace
}  // namespace masa::test
