// One SAC (or TD3: sac.algorithm) run in one process: a single environment of a catalog task steps
// with the policy's samples (TD3: tanh(mean) plus Gaussian noise; uniform random actions for the
// first sac.learning_starts steps), every transition goes
// into the replay buffer, and once learning started each environment step is followed by
// sac.updates_per_step gradient steps. The observation normalizer is fitted once, on the random
// steps, and then held fixed (Q's inputs do not drift). Writes config.yaml, metrics.csv (a row and
// a progress line every sac.log_every steps), policy.bin (with every evaluation: the common policy
// file, sac_policy_file.hpp, that masa_eval, masa_export and masa_deploy read) and
// sac_state.bin every sac.checkpoint_every steps and at the end: the trainer, the replay buffer,
// the generator and the environment mid-episode, so that a resumed run goes on exactly as if it
// had not stopped (the same metrics rows, clocks aside).
#pragma once

#include <memory>
#include <string>

#include "common/config/run_config.hpp"

namespace masa::sac {

struct SacRunOptions {
  std::string run_dir;
  bool verbose = true;
  bool resume = false;  // go on from run_dir/sac_state.bin, appending to metrics.csv
};

struct SacRunResult {
  double final_eval_return = 0;
  long long env_steps = 0, updates = 0;
};

class SacRun {
 public:
  SacRun(const config::RunConfig& rc, SacRunOptions options);
  ~SacRun();
  SacRunResult run();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace masa::sac
