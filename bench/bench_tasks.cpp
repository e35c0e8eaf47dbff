// Env steps per second per core for every task under random actions, next to raw mj_step
// throughput of the same model with the same frame skip, so that the cost of observation, reward
// and bookkeeping is visible. Run on one core:
//   taskset -c 0 build/bench/bench_tasks --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "common/config/run_config.hpp"
#include "common/task/registry.hpp"

namespace {

using namespace masa;

struct Prepared {
  std::unique_ptr<task::TaskFactory> factory;
};

Prepared prepare(const std::string& name) {
  const auto rc = config::loadRunConfig(config::defaultConfigsDir(), {"task=" + name});
  return {std::make_unique<task::TaskFactory>(rc.task, sym::SymmetrySpec::load(rc.spec_path), rc.env, rc.origin)};
}

// Random actions are drawn up front: the benchmark measures the task, not the generator.
std::vector<float> randomActions(int dim, int count, Rng& rng) {
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<float> a(static_cast<size_t>(dim) * count);
  for (float& v : a) v = u(rng);
  return a;
}

void taskStep(benchmark::State& state, const std::string& name) {
  auto p = prepare(name);
  auto env = p.factory->create();
  Rng rng(0);
  const int n = 4096;
  const auto actions = randomActions(env->actDim(), n, rng);
  std::vector<float> obs(env->obsDim());
  env->reset(rng);
  long k = 0;
  for (auto _ : state) {
    const auto o = env->step(actions.data() + (k++ % n) * env->actDim());
    env->observe(obs.data());
    benchmark::DoNotOptimize(obs.data());
    if (o.terminated || o.truncated) env->reset(rng);
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["frame_skip"] = env->controlTimestep() / env->model()->opt.timestep;
}

void rawMjStep(benchmark::State& state, const std::string& name) {
  auto p = prepare(name);
  auto env = p.factory->create();
  Rng rng(0);
  const int n = 4096, skip = static_cast<int>(std::lround(env->controlTimestep() / env->model()->opt.timestep));
  const mjModel* m = env->model();
  mjData* d = env->data();
  const auto ctrls = randomActions(m->nu, n, rng);
  env->reset(rng);
  long k = 0;
  for (auto _ : state) {
    const float* c = ctrls.data() + (k % n) * m->nu;
    for (int a = 0; a < m->nu; ++a) d->ctrl[a] = c[a];
    for (int s = 0; s < skip; ++s) mj_step(m, d);
    // Same reset cadence as a failing random policy would see, without the task's checks.
    if (++k % 64 == 0) env->reset(rng);
  }
  state.SetItemsProcessed(state.iterations());
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  for (const std::string& name : masa::task::registeredTasks()) {
    if (name == "mjcf") continue;
    benchmark::RegisterBenchmark(("RawMjStep/" + name).c_str(), rawMjStep, name);
    benchmark::RegisterBenchmark(("TaskStep/" + name).c_str(), taskStep, name);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
