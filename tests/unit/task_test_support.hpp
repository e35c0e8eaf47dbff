// Plumbing shared by the task tests (tests/unit/test_task_*.cpp): building a task as shipped in
// configs/ (or with its env or spec edited for one test), the random rollout and the seed
// determinism run every task goes through, lookups by name, and the verifier's worst entries.
// Kept in one place so that every task is driven the same way. The helpers check only what all
// tasks check alike (finite values, bit-identical reruns, the time limit); the expectations
// particular to a task (dimensions, episode counts, tolerances, names) stay in its test.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/config/run_config.hpp"
#include "common/sim/registry.hpp"
#include "common/physics_symmetry/symmetry_verifier.hpp"
#include "tasks/tasks.hpp"

namespace masa::test {

// ---- The shipped configuration of a task ----------------------------------------------------
// configs/tasks/<task>.yaml holds the run config (its env section feeds the task) and
// configs/specs/<task>.yaml the symmetry spec.

inline std::string configsDir() { return std::string(MASA_SOURCE_DIR) + "/configs"; }
inline std::string shippedSpecPath(const std::string& task) { return configsDir() + "/specs/" + task + ".yaml"; }
inline sym::SymmetrySpec shippedSpec(const std::string& task) { return sym::SymmetrySpec::load(shippedSpecPath(task)); }

inline std::string readTextFile(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << "cannot read " << path;
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The env section of configs/tasks/<task>.yaml, deep-copied: a test may edit it freely.
inline YAML::Node shippedEnv(const std::string& task) {
  return YAML::Clone(YAML::LoadFile(configsDir() + "/tasks/" + task + ".yaml")["env"]);
}

// The shipped env after `edit(YAML::Node& env)`: reset noise off, a shorter time limit, ...
template <class Edit>
YAML::Node editedEnv(const std::string& task, Edit edit) {
  YAML::Node env = shippedEnv(task);
  edit(env);
  return env;
}

// The shipped spec after `edit(YAML::Node& root)` on its YAML tree: the broken specs the verifier
// must refute. Emitted and parsed again, as a spec file written that way would be.
template <class Edit>
sym::SymmetrySpec editedSpec(const std::string& task, Edit edit) {
  YAML::Node root = YAML::LoadFile(shippedSpecPath(task));
  edit(root);
  YAML::Emitter out;
  out << root;
  return sym::SymmetrySpec::parseString(out.c_str(), "edited " + task + ".yaml");
}

// A factory straight from an env node (no run-config defaults, no origins for error messages).
inline task::TaskFactory envFactory(const std::string& task, const YAML::Node& env, const sym::SymmetrySpec& spec) {
  return task::TaskFactory(task::taskCatalog(), task, spec, env);
}
inline task::TaskFactory envFactory(const std::string& task, const YAML::Node& env) {
  return envFactory(task, env, shippedSpec(task));
}
inline task::TaskFactory envFactory(const std::string& task) { return envFactory(task, shippedEnv(task)); }

// The task as a training run builds it: configs/ through loadRunConfig (defaults merged, origins
// kept, the spec the run config names), with key=value overrides such as "env.max_episode_steps=5".
inline task::TaskFactory runConfigFactory(const std::string& task, const std::vector<std::string>& overrides = {}) {
  std::vector<std::string> all = {"task=" + task};
  all.insert(all.end(), overrides.begin(), overrides.end());
  const config::RunConfig rc = config::loadRunConfig(configsDir(), all);
  return task::TaskFactory(task::taskCatalog(), task, sym::SymmetrySpec::load(rc.spec_path), rc.env, rc.origin);
}
// The same with another spec in place of the shipped one.
inline task::TaskFactory runConfigFactory(const std::string& task, const sym::SymmetrySpec& spec) {
  const config::RunConfig rc = config::loadRunConfig(configsDir(), {"task=" + task});
  return task::TaskFactory(task::taskCatalog(), task, spec, rc.env, rc.origin);
}

// ---- Reading and driving a task --------------------------------------------------------------

// Index of an observation dimension by its spec name (spec().obsNames(), e.g. "central.torso_z").
inline int obsIndex(const task::Task& t, const std::string& name) {
  const auto& names = t.spec().obsNames();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it != names.end()) return static_cast<int>(it - names.begin());
  ADD_FAILURE() << "no observation " << name;
  return 0;
}

inline int termIndex(const task::Task& t, const std::string& name) {
  const auto& names = t.rewardTermNames();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it != names.end()) return static_cast<int>(it - names.begin());
  ADD_FAILURE() << "no reward term " << name;
  return 0;
}

// A weighted reward term of the last step, by name.
inline double rewardTerm(const task::Task& t, const std::string& name) { return t.rewardTerms()[termIndex(t, name)]; }

inline std::vector<float> observation(const task::Task& t) {
  std::vector<float> o(t.obsDim());
  t.observe(o.data());
  return o;
}

inline task::StepOutcome stepZero(task::Task& t) {
  const std::vector<float> zero(t.actDim(), 0.0f);
  return t.step(zero.data());
}

// Zero actions for `steps` steps against a time limit of `steps`: none terminates and only the last
// is truncated. `last` gets the final outcome. Call it inside ASSERT_NO_FATAL_FAILURE.
inline void stepZeroToTimeLimit(task::Task& t, int steps, task::StepOutcome& last) {
  for (int s = 0; s < steps; ++s) {
    last = stepZero(t);
    ASSERT_FALSE(last.terminated);
    EXPECT_EQ(last.truncated, s == steps - 1);
  }
}

// A joint's first qpos / qvel entry, by joint name (for a free joint: position, then quaternion /
// linear, then angular velocity).
inline int jointId(const task::Task& t, const char* joint) {
  const int j = mj_name2id(t.model(), mjOBJ_JOINT, joint);
  EXPECT_GE(j, 0) << "no joint " << joint;
  return std::max(j, 0);
}
inline double* jointQpos(task::Task& t, const char* joint) {
  return t.data()->qpos + t.model()->jnt_qposadr[jointId(t, joint)];
}
inline double* jointQvel(task::Task& t, const char* joint) {
  return t.data()->qvel + t.model()->jnt_dofadr[jointId(t, joint)];
}

// ---- The humanoids' tilt termination (env.max_tilt_deg, tasks/humanoid_tightrope/humanoid_body) --

// One zero-action step of a humanoid task after its torso was pitched forward by tilt_deg in place
// (the free joint "root": its height, and the task's other terminations, stay as they were), with
// env.max_tilt_deg set to max_tilt_deg and no reset noise.
inline task::StepOutcome stepWithTorsoTilted(const std::string& task_name, double max_tilt_deg, double tilt_deg) {
  task::TaskFactory f = envFactory(task_name, editedEnv(task_name, [&](YAML::Node& env) {
                                     env["reset_noise"] = 0.0;
                                     env["max_tilt_deg"] = max_tilt_deg;
                                   }));
  auto t = f.create();
  Rng rng(0);
  t->reset(rng);
  const double half = 0.5 * tilt_deg * M_PI / 180.0;
  double* q = jointQpos(*t, "root") + 3;  // the quaternion: w, x, y, z
  q[0] = std::cos(half), q[1] = 0.0, q[2] = std::sin(half), q[3] = 0.0;
  mj_forward(t->model(), t->data());
  return stepZero(*t);
}

// The paper's task (0) never ends on a tilt; 30 degrees lets 20 pass and ends 40 with exactly the
// termination reward; values outside [0, 180) are refused naming the key.
inline void expectTiltTerminationOnlyWhenSet(const std::string& task_name) {
  EXPECT_FALSE(stepWithTorsoTilted(task_name, 0.0, 60.0).terminated);
  EXPECT_FALSE(stepWithTorsoTilted(task_name, 30.0, 20.0).terminated);
  const task::StepOutcome o = stepWithTorsoTilted(task_name, 30.0, 40.0);
  EXPECT_TRUE(o.terminated);
  EXPECT_FALSE(o.truncated);
  EXPECT_EQ(o.reward, -1.0);
  for (double bad : {-5.0, 180.0}) {
    try {
      envFactory(task_name, editedEnv(task_name, [&](YAML::Node& env) { env["max_tilt_deg"] = bad; })).create();
      ADD_FAILURE() << task_name << ": max_tilt_deg " << bad << " was accepted";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("env.max_tilt_deg"), std::string::npos) << e.what();
    }
  }
}

// ---- Random rollouts and determinism -----------------------------------------------------------

struct RandomStepChecks {
  bool contact_buffers = false;   // MuJoCo never ran out of contact / constraint slots
  bool never_terminates = false;  // tasks whose episodes end only by the time limit
};

// `steps` uniform random actions in [-1, 1] from reset(Rng(seed)), resetting whenever an episode
// ends; fails fatally at the first non-finite reward or observation (or failed extra check), and
// adds the finished episodes to `episodes`. Call it inside ASSERT_NO_FATAL_FAILURE.
inline void runRandomSteps(task::Task& t, std::uint64_t seed, int steps, int& episodes,
                           const RandomStepChecks& checks = {}) {
  Rng rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> obs(t.obsDim()), act(t.actDim());
  t.reset(rng);
  for (int s = 0; s < steps; ++s) {
    for (float& a : act) a = u(rng);
    const task::StepOutcome o = t.step(act.data());
    t.observe(obs.data());
    ASSERT_TRUE(std::isfinite(o.reward)) << "step " << s;
    if (checks.contact_buffers) {
      ASSERT_EQ(t.data()->warning[mjWARN_CONTACTFULL].number, 0) << "nconmax too small";
      ASSERT_EQ(t.data()->warning[mjWARN_CNSTRFULL].number, 0) << "njmax too small";
    }
    for (int d = 0; d < t.obsDim(); ++d)
      ASSERT_TRUE(std::isfinite(obs[d])) << "step " << s << " obs " << d << " " << t.spec().obsNames()[d];
    if (checks.never_terminates) {
      ASSERT_FALSE(o.terminated) << "step " << s;
    }
    if (o.terminated || o.truncated) {
      ++episodes;
      t.reset(rng);
    }
  }
}

struct TrajectoryOptions {
  enum class Observe { kAfterStep, kBeforeStep };
  int steps = 150;
  Observe observe = Observe::kAfterStep;  // the observation recorded with each step
  bool record_reward = true;              // the step's reward after its observation
  // Task-specific values appended after each step's record (before a reset).
  std::function<void(const task::Task&, std::vector<float>&)> extra = nullptr;
};

// Everything a rollout of uniform random actions from reset(Rng(seed)) observes, as one vector:
// what the determinism tests compare bit for bit. Resets whenever an episode ends.
inline std::vector<float> recordTrajectory(const task::TaskFactory& f, std::uint64_t seed,
                                           const TrajectoryOptions& opt = {}) {
  auto t = f.create();
  Rng rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> out, obs(t->obsDim()), act(t->actDim());
  auto record = [&] {
    t->observe(obs.data());
    out.insert(out.end(), obs.begin(), obs.end());
  };
  t->reset(rng);
  for (int s = 0; s < opt.steps; ++s) {
    if (opt.observe == TrajectoryOptions::Observe::kBeforeStep) record();
    for (float& a : act) a = u(rng);
    const task::StepOutcome o = t->step(act.data());
    if (opt.observe == TrajectoryOptions::Observe::kAfterStep) record();
    if (opt.record_reward) out.push_back(static_cast<float>(o.reward));
    if (opt.extra) opt.extra(*t, out);
    if (o.terminated || o.truncated) t->reset(rng);
  }
  return out;
}

// Two recordings with `seed` are bit-identical (memcmp: -0.0 and NaN payloads count) and one with
// `other_seed` differs, so the seed really drives the randomness.
inline void expectSameSeedBitIdenticalOtherSeedDiffers(const std::function<std::vector<float>(std::uint64_t)>& record,
                                                       std::uint64_t seed, std::uint64_t other_seed) {
  const std::vector<float> a = record(seed), b = record(seed), c = record(other_seed);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(float)));
  EXPECT_NE(a, c);
}

// ---- Verifier reports ---------------------------------------------------------------------------

// The entry with the largest error: the one a broken spec must be named by. `v` must not be empty.
inline task::NamedError worstEntry(const std::vector<task::NamedError>& v) {
  EXPECT_FALSE(v.empty());
  if (v.empty()) return {};
  return *std::max_element(v.begin(), v.end(),
                           [](const task::NamedError& a, const task::NamedError& b) { return a.error < b.error; });
}

// The largest error among the entries whose name passes `keep` (0 when none does).
template <class Keep>
double worstError(const std::vector<task::NamedError>& v, Keep keep) {
  double worst = 0.0;
  for (const task::NamedError& e : v)
    if (keep(e.name)) worst = std::max(worst, e.error);
  return worst;
}
inline double worstError(const std::vector<task::NamedError>& v) {
  return worstError(v, [](const std::string&) { return true; });
}

}  // namespace masa::test
