// Every algorithm the Learner can run, by the run config's `learner` key: the programs
// (masa_learner, masa_train) hand this to LearnerOptions::make_algorithm. It sits above the
// algorithms' libraries, so the Learner itself names none.
#pragma once

#include <memory>

#include "common/cluster/communicator.hpp"
#include "common/config/run_config.hpp"
#include "learner/algorithm.hpp"

namespace masa::learner {

// `learner: ppo` -> PPO (learner/ppo_algorithm.hpp); `learner: off_policy` -> SAC or TD3 on a
// replay (learner/sac/off_policy_rule.hpp). Initializes the networks from rng.
std::unique_ptr<Algorithm> makeAlgorithm(const config::RunConfig& rc, Rng& rng, cluster::Communicator& ranks);

}  // namespace masa::learner
