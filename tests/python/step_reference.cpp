// The C++ side of the Python module's step test: N environments of a task built and stepped the
// way the actors do (TaskFactory, Task::reset from Rng(seed + e), Task::step, a reset when an
// episode ends), without the module's code. Reads the actions (float32, steps x N x act_dim) and
// writes per step the observations (float32, N x obs_dim), the rewards (float64, N), terminated
// and truncated (one byte each, N), for test_step_equals_cpp.py to compare bit for bit.
//   masa_python_step_reference <task> <num_envs> <seed> <steps> <actions.bin> <out.bin> [key=value ...]
// (config overrides as masa_train's --set, after task=<task>)
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "common/config/run_config.hpp"
#include "tasks/tasks.hpp"

using namespace masa;

int main(int argc, char** argv) {
  if (argc < 7) {
    std::cerr << "usage: masa_python_step_reference <task> <num_envs> <seed> <steps> <actions.bin> <out.bin> [key=value ...]\n";
    return 2;
  }
  try {
    const std::string task = argv[1];
    const int n = std::atoi(argv[2]);
    const uint64_t seed = std::strtoull(argv[3], nullptr, 10);
    const int steps = std::atoi(argv[4]);
    std::vector<std::string> overrides{"task=" + task};
    for (int k = 7; k < argc; ++k) overrides.emplace_back(argv[k]);
    const auto config = config::loadRunConfig(config::defaultConfigsDir(), overrides);
    const auto spec = sym::SymmetrySpec::load(config.spec_path);
    task::TaskFactory factory(task::taskCatalog(), config.task, spec, config.env, config.origin);
    std::vector<std::unique_ptr<task::Task>> envs;
    std::vector<Rng> rngs;
    for (int e = 0; e < n; ++e) {
      envs.push_back(factory.create());
      rngs.emplace_back(seed + static_cast<uint64_t>(e));
      envs[e]->reset(rngs[e]);
    }
    const int obs_dim = envs[0]->obsDim(), act_dim = envs[0]->actDim();
    std::vector<float> actions(static_cast<size_t>(steps) * n * act_dim);
    std::ifstream in(argv[5], std::ios::binary);
    if (!in.read(reinterpret_cast<char*>(actions.data()), static_cast<std::streamsize>(actions.size() * sizeof(float))))
      throw std::runtime_error(std::string(argv[5]) + ": fewer actions than steps x num_envs x act_dim");
    std::ofstream out(argv[6], std::ios::binary);
    std::vector<float> obs(static_cast<size_t>(n) * obs_dim);
    std::vector<double> reward(n);
    std::vector<char> terminated(n), truncated(n);
    for (int e = 0; e < n; ++e) envs[e]->observe(obs.data() + static_cast<size_t>(e) * obs_dim);
    out.write(reinterpret_cast<const char*>(obs.data()), static_cast<std::streamsize>(obs.size() * sizeof(float)));
    for (int t = 0; t < steps; ++t) {
      for (int e = 0; e < n; ++e) {
        const task::StepOutcome r = envs[e]->step(actions.data() + (static_cast<size_t>(t) * n + e) * act_dim);
        reward[e] = r.reward;
        terminated[e] = r.terminated;
        truncated[e] = r.truncated;
        if (r.terminated || r.truncated) envs[e]->reset(rngs[e]);
        envs[e]->observe(obs.data() + static_cast<size_t>(e) * obs_dim);
      }
      out.write(reinterpret_cast<const char*>(obs.data()), static_cast<std::streamsize>(obs.size() * sizeof(float)));
      out.write(reinterpret_cast<const char*>(reward.data()), static_cast<std::streamsize>(reward.size() * sizeof(double)));
      out.write(terminated.data(), n);
      out.write(truncated.data(), n);
    }
    if (!out) throw std::runtime_error(std::string(argv[6]) + ": cannot write");
  } catch (const std::exception& e) {
    std::cerr << "masa_python_step_reference: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
