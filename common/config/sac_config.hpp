// The `sac` section of a run configuration (configs/defaults.yaml documents every key): the
// off-policy learner's numbers, SAC's or TD3's (sac.algorithm). defaults.yaml is the schema, so a key it lacks is an error.
#pragma once

#include <string>
#include <vector>

#include "common/config/run_config.hpp"
#include "common/model/sac_policy.hpp"

namespace masa::sac {

struct SacConfig {
  std::string algorithm = "sac";  // sac | td3 (td3_trainer.hpp)
  long long env_steps = 1000000;
  long long buffer_size = 1000000;
  int batch_size = 256;
  long long learning_starts = 5000;
  double updates_per_step = 1;  // may be fractional: gradient steps owed = floor(ratio x steps past learning_starts)
  int threads = 1;  // learner: off_policy: OpenMP threads of the gradient steps
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
  // TD3 only (Fujimoto et al. 2018's numbers).
  double td3_exploration_noise = 0.1;  // std of the Gaussian added to tanh(mean) when collecting
  double td3_policy_noise = 0.2;       // std of the target policy smoothing noise
  double td3_noise_clip = 0.5;         // the smoothing noise clipped to +-this
  int td3_policy_delay = 2;            // critic steps per actor step (and target move)
  // Hindsight relabeling (learner/sac/hindsight.hpp): the share of each batch whose goal becomes one
  // achieved later in the same episode ("future"), drawn among the next her_future_window steps
  // (0: to the episode's newest stored step). HER's k relabeled goals per real one is k/(k+1).
  double her_share = 0.0;
  long long her_future_window = 0;
  // The learner's state keeps this many of the newest transitions (-1: the whole replay). A run
  // resumed from fewer refills to learning_starts before its gradient steps go on.
  long long checkpoint_replay = -1;
};

// Reads rc.resolved["sac"] (config::sectionOf); throws masa::ConfigError naming the key path
// (sac.polyak) and the file that set it. Every number must be finite.
SacConfig readSacConfig(const config::RunConfig& rc);

// The SAC policy's shape of a run: the sac section's widths and bounds, the model section's
// activation and SASA weight (masa_sac's learner and the off-policy actors build the same policy).
SacPolicyShape policyShape(const config::RunConfig& rc, const SacConfig& sc);

// Gradient steps owed once `steps_past_start` transitions arrived since learning started:
// floor(updates_per_step x steps_past_start) (0 before). A fractional ratio spreads them evenly.
long long gradientStepsOwed(const SacConfig& sc, long long steps_past_start);

}  // namespace masa::sac
