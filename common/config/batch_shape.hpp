// What a PPO batch must satisfy before a learner is built from a run config: its minibatches divide
// it, and its environments divide among the learner ranks. These are a user's settings, so they
// are refused as ConfigErrors naming the keys and what to change, never as an internal check.
#pragma once

#include "common/config/run_config.hpp"

namespace masa::config {

// Throws ConfigError (naming ppo.minibatch_size or the learner's num_envs and the file that set it) where
// the PPO batch of `config` cannot be split as the learner splits it over `learner_ranks` ranks.
// Off-policy runs have no PPO minibatches and pass.
void checkBatchShape(const RunConfig& config, int learner_ranks);

}  // namespace masa::config
