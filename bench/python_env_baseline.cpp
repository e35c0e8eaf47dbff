// The C++ side of bench/python_env_throughput.py: env steps per second of N environments of one
// task stepped the way the actor steps them (OpenMP over environments, step, observe, a reset when
// an episode ends), without a policy, on the same actions the Python side sends through the module.
//   bench_python_env_baseline <task> <num_envs> <threads> <steps>
// prints "steps_per_s <value>". Actions: 16 blocks of uniform draws from Rng(1), cycled.
#include <omp.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "common/config/run_config.hpp"
#include "tasks/tasks.hpp"

using namespace masa;

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: bench_python_env_baseline <task> <num_envs> <threads> <steps>\n");
    return 2;
  }
  const std::string name = argv[1];
  const int n = std::atoi(argv[2]), threads = std::atoi(argv[3]), steps = std::atoi(argv[4]);
  const auto rc = config::loadRunConfig(config::defaultConfigsDir(), {"task=" + name});
  task::TaskFactory factory(task::taskCatalog(), rc.task, sym::SymmetrySpec::load(rc.spec_path), rc.env, rc.origin);
  std::vector<std::unique_ptr<task::Task>> envs;
  std::vector<Rng> rngs;
  for (int e = 0; e < n; ++e) {
    envs.push_back(factory.create());
    rngs.emplace_back(static_cast<uint64_t>(e));
    envs[e]->reset(rngs[e]);
  }
  const int obs_dim = envs[0]->obsDim(), act_dim = envs[0]->actDim();
  constexpr int kBlocks = 16;
  std::vector<float> actions(static_cast<size_t>(kBlocks) * n * act_dim);
  Rng act_rng(1);
  std::uniform_real_distribution<float> u(-1, 1);
  for (float& a : actions) a = u(act_rng);
  std::vector<float> obs(static_cast<size_t>(n) * obs_dim);
  std::vector<double> reward(n);
  const auto began = std::chrono::steady_clock::now();
  for (int t = 0; t < steps; ++t) {
    const float* block = actions.data() + static_cast<size_t>(t % kBlocks) * n * act_dim;
#pragma omp parallel for num_threads(threads) schedule(static)
    for (int e = 0; e < n; ++e) {
      const task::StepOutcome r = envs[e]->step(block + static_cast<size_t>(e) * act_dim);
      reward[e] = r.reward;
      if (r.terminated || r.truncated) envs[e]->reset(rngs[e]);
      envs[e]->observe(obs.data() + static_cast<size_t>(e) * obs_dim);
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  std::printf("steps_per_s %.1f\n", static_cast<double>(steps) * n / seconds);
  return 0;
}
