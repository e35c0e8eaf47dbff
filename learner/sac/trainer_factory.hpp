// The trainer sac.algorithm names: SAC (sac_trainer.hpp) or TD3 (td3_trainer.hpp), on networks the
// caller owns and has initialized (TD3 copies the policy into its target here).
#pragma once

#include <memory>

#include "common/config/sac_config.hpp"
#include "common/model/sac_policy.hpp"
#include "learner/offline/twin_q.hpp"
#include "learner/sac/off_policy_trainer.hpp"

namespace masa::sac {

std::unique_ptr<OffPolicyTrainer<float>> makeTrainer(const SacConfig& sc, const sym::SymmetrySpec& spec,
                                                     SacPolicy<float>& policy, offline::TwinQ<float>& q,
                                                     offline::TwinQ<float>& q_target);

}  // namespace masa::sac
