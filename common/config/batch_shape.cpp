#include "common/config/batch_shape.hpp"

#include <cstdint>
#include <string>

#include "common/core/config_error.hpp"

namespace masa::config {

void checkBatchShape(const RunConfig& config, int learner_ranks) {
  const PpoConfig& p = config.ppo;
  const RolloutShape& shape = config.rollout;
  const ConfigSection top = sectionOf(config, "");
  if (learner_ranks > 1 && shape.num_envs % learner_ranks != 0)
    throw ConfigError(top.originOf(shape.key("num_envs")), shape.key("num_envs"),
                      std::to_string(shape.num_envs) + " environments do not divide among " + std::to_string(learner_ranks) +
                          " learner ranks: give a multiple of the ranks (the launchers take actors x environments)");
  if (config.learner == "off_policy") return;
  const int64_t batch = static_cast<int64_t>(shape.num_envs) * shape.horizon;
  if (batch % p.minibatch_size != 0)
    throw ConfigError(top.originOf("ppo.minibatch_size"), "ppo.minibatch_size",
                      std::to_string(p.minibatch_size) + " does not divide the batch, ppo.num_envs x ppo.horizon = " +
                          std::to_string(shape.num_envs) + " x " + std::to_string(shape.horizon) + " = " + std::to_string(batch) +
                          ": set a divisor of it (deploy/train.sh and the cluster launchers size it for you)");
}

}  // namespace masa::config
