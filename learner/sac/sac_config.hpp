// The `sac` section of a run configuration (configs/defaults.yaml documents every key): the
// off-policy learner's numbers. defaults.yaml is the schema, so a key it lacks is an error.
#pragma once

#include <vector>

#include "common/config/run_config.hpp"

namespace masa::sac {

struct SacConfig {
  long long env_steps = 1000000;
  long long buffer_size = 1000000;
  int batch_size = 256;
  long long learning_starts = 5000;
  int updates_per_step = 1;
  int n_step = 1;
  double discount = 0.99;
  double polyak = 0.005;
  double policy_lr = 3e-4, q_lr = 3e-4, alpha_lr = 3e-4;
  double init_alpha = 1.0;
  bool autotune = true;
  double target_entropy_per_dim = -1.0;
  std::vector<int> policy_hidden{256, 256}, q_hidden{256, 256};
  double log_std_min = -5.0, log_std_max = 2.0;
  long long log_every = 1000;
  long long eval_every = 10000;
  int eval_episodes = 5;
  long long checkpoint_every = 10000;  // env steps; a multiple of log_every (0: only at the end)
};

// Reads rc.resolved["sac"] (config::sectionOf); throws masa::ConfigError naming the key path
// (sac.polyak) and the file that set it. Every number must be finite.
SacConfig readSacConfig(const config::RunConfig& rc);

}  // namespace masa::sac
