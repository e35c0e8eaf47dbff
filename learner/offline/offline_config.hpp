// The `offline` section of a run configuration (configs/defaults.yaml documents every key): which
// algorithm, whether the data is augmented (SASA-data), and the numbers of BC and IQL.
#pragma once

#include <string>
#include <vector>

#include "common/config/run_config.hpp"

namespace masa::offline {

enum class Algo { kBc, kIql };
enum class BcLoss { kGaussian, kMse };

struct OfflineConfig {
  Algo algo = Algo::kIql;
  bool augment = false;
  long long steps = 1000000;
  int batch_size = 256;
  double learning_rate = 3e-4;
  BcLoss bc_loss = BcLoss::kGaussian;
  double expectile = 0.7;
  double beta = 3.0;
  double max_weight = 100.0;
  double discount = 0.99;
  double polyak = 0.005;
  std::vector<int> q_hidden{256, 256};
  double log_std_min = -5.0, log_std_max = 2.0;
  bool normalize_reward = false;
  int log_every = 1000;
  long long eval_every = 50000;
  int eval_episodes = 10;
  int final_eval_episodes = 100;
};

// Reads rc.resolved["offline"] (config::sectionOf); throws masa::ConfigError naming the key path
// (offline.beta) and the file that set it. Every number must be finite.
OfflineConfig readOfflineConfig(const config::RunConfig& rc);

std::string algoName(Algo algo);  // "bc" | "iql"

}  // namespace masa::offline
