// Env steps per second per core for every task under random actions, next to the bare physics
// of the same steps, so that the cost of observation, reward and bookkeeping is visible.
//
// Both benchmarks replay one recorded sequence: random actions and the steps where episodes
// ended, from one seed. TaskStep runs Task::step + observe; PhysicsOnly runs Task::advancePhysics
// (clamp, actuation, frame-skip mj_step substeps with the task's PD loop) on the same actions
// with resets at the same steps, i.e. the same trajectory without the task's own work.
// Randomized runs TaskStep with env.randomization on (issue #52: every key, a draw per episode),
// against TaskStep for the cost of the randomization (target: >= 0.95 of TaskStep's rate):
//   taskset -c 1 build/bench/bench_tasks --benchmark_filter='TaskStep/a1_beam|Randomized/a1_beam'
//   taskset -c 1 build/bench/bench_tasks --benchmark_repetitions=5
//       --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>

#include "common/config/run_config.hpp"
#include "common/sim/registry.hpp"
#include "tasks/tasks.hpp"

namespace {

using namespace masa;

constexpr std::uint64_t kSeed = 0;
constexpr int kSteps = 2048;

struct Replay {
  std::unique_ptr<task::TaskFactory> factory;
  std::vector<float> actions;  // kSteps x act_dim
  std::vector<char> done;      // episode ended at this step: reset before the next
};

// Every randomization key at once: what a sim-to-real run would draw (docs/randomization.md).
const std::string kRandomization =
    "env.randomization={mass_scale: [0.8, 1.2], geom_friction_scale: [0.5, 1.25], joint_damping_scale: [0.5, 1.5], "
    "joint_friction_scale: [0.5, 1.5], actuator_strength: [0.85, 1.15], latency_steps: [0, 1.5], obs_noise_std: 0.01, "
    "obs_bias: 0.02}";

Replay record(const std::string& name, bool randomized) {
  std::vector<std::string> sets = {"task=" + name};
  if (randomized) sets.push_back(kRandomization);
  const auto rc = config::loadRunConfig(config::defaultConfigsDir(), sets);
  Replay r{std::make_unique<task::TaskFactory>(task::taskCatalog(), rc.task, sym::SymmetrySpec::load(rc.spec_path), rc.env, rc.origin), {}, {}};
  auto env = r.factory->create();
  Rng act_rng(kSeed + 1), reset_rng(kSeed);
  std::uniform_real_distribution<float> u(-1, 1);
  r.actions.resize(static_cast<size_t>(kSteps) * env->actDim());
  for (float& a : r.actions) a = u(act_rng);
  r.done.resize(kSteps);
  env->reset(reset_rng);
  for (int k = 0; k < kSteps; ++k) {
    const auto o = env->step(r.actions.data() + static_cast<size_t>(k) * env->actDim());
    r.done[k] = o.terminated || o.truncated;
    if (r.done[k]) env->reset(reset_rng);
  }
  return r;
}

template <bool kFullStep, bool kRandomized = false>
void replay(benchmark::State& state, const std::string& name) {
  const Replay r = record(name, kRandomized);
  auto env = r.factory->create();
  std::vector<float> obs(env->obsDim());
  Rng reset_rng(kSeed);
  env->reset(reset_rng);
  int k = 0;
  for (auto _ : state) {
    const float* a = r.actions.data() + static_cast<size_t>(k) * env->actDim();
    if constexpr (kFullStep) {
      env->step(a);
      env->observe(obs.data());
      benchmark::DoNotOptimize(obs.data());
    } else {
      env->advancePhysics(a);
    }
    if (r.done[k]) env->reset(reset_rng);
    if (++k == kSteps) {  // start the recorded sequence over, from the same seed
      k = 0;
      reset_rng.seed(kSeed);
      env->reset(reset_rng);
    }
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["frame_skip"] = std::round(env->controlTimestep() / env->model()->opt.timestep);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  // Every task config (configs/tasks/NAME.yaml: the shipped tasks and those written in YAML), not
  // the registered task codes: "yaml" and "mjcf" are code for configs, not tasks of their own (the
  // benchmark used to abort on them, "unknown task 'yaml'").
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(masa::config::defaultConfigsDir() + "/tasks"))
    if (entry.path().extension() == ".yaml") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  for (const std::string& name : names) {
    benchmark::RegisterBenchmark(("PhysicsOnly/" + name).c_str(), replay<false>, name);
    benchmark::RegisterBenchmark(("TaskStep/" + name).c_str(), replay<true>, name);
    benchmark::RegisterBenchmark(("Randomized/" + name).c_str(), replay<true, true>, name);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
