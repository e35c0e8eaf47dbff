// N instances of one task stepped together, for the Python module's vector environment: the tasks
// the actors build (the run config's TaskFactory), each with its own generator, stepped in parallel
// over OpenMP into buffers the caller owns (the NumPy arrays handed back to Python, written once).
//
// Seeds: reset(seed) restarts environment e from Rng(seed + e), the seeds masa_eval gives its
// episodes, so a Python loop over a policy replays masa_eval's episodes. An environment whose
// episode ends is reset at once from its own generator (the actors' rule); the observation of the
// ended episode's last state goes to final_obs.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "common/config/run_config.hpp"
#include "common/sim/registry.hpp"

namespace masa::python {

// Where one step writes, each an array of numEnvs() rows.
struct StepBuffers {
  float* obs = nullptr;            // num_envs x obs_dim: after the step (after the reset for ended episodes)
  double* reward = nullptr;        // num_envs
  bool* terminated = nullptr;      // num_envs
  bool* truncated = nullptr;       // num_envs
  bool* episode_ended = nullptr;   // num_envs: terminated or truncated, the environment was reset
  float* final_obs = nullptr;      // num_envs x obs_dim: the ended episode's last observation (else zeros)
  double* episode_return = nullptr;  // num_envs: the ended episode's return (else 0)
  int32_t* episode_length = nullptr;  // num_envs: its length (else 0)
  int8_t* episode_success = nullptr;  // num_envs: 1 / 0, -1 when the task has no success (or no episode ended)
};

class BatchedEnv {
 public:
  // Throws what TaskFactory throws (ConfigError, std::runtime_error) for a config it cannot build.
  BatchedEnv(const config::RunConfig& config, const sym::SymmetrySpec& spec, int num_envs, int threads);

  int numEnvs() const { return static_cast<int>(envs_.size()); }
  int obsDim() const { return envs_[0]->obsDim(); }
  int actDim() const { return envs_[0]->actDim(); }
  int maxEpisodeSteps() const { return envs_[0]->maxEpisodeSteps(); }
  double controlTimestep() const { return envs_[0]->controlTimestep(); }
  const std::string& taskName() const { return factory_->name(); }
  const sym::SymmetrySpec& spec() const { return spec_; }
  const std::vector<std::string>& rewardTermNames() const { return envs_[0]->rewardTermNames(); }
  const task::Task& env(int e) const { return *envs_.at(static_cast<size_t>(e)); }

  // reset and step take a lock: Python threads may call them at once with the GIL released.
  // Environment e restarts from Rng(seed + e); obs: num_envs x obs_dim.
  void reset(uint64_t seed, float* obs);
  // Every environment restarts from its own generator as it stands (no new seeds).
  void resetContinuing(float* obs);
  // actions: num_envs x act_dim, in [-1, 1] (the tasks clamp).
  void step(const float* actions, const StepBuffers& out);

 private:
  void resetEnvironments(float* obs);  // each from its generator as it stands; the lock held

  sym::SymmetrySpec spec_;
  std::unique_ptr<task::TaskFactory> factory_;
  std::vector<std::unique_ptr<task::Task>> envs_;
  std::vector<Rng> rngs_;
  int threads_;
  std::mutex busy_;
};

}  // namespace masa::python
