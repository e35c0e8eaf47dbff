#include "learner/sac/trainer_factory.hpp"

#include "learner/sac/sac_trainer.hpp"
#include "learner/sac/td3_trainer.hpp"

namespace masa::sac {

std::unique_ptr<OffPolicyTrainer<float>> makeTrainer(const SacConfig& sc, const sym::SymmetrySpec& spec,
                                                     SacPolicy<float>& policy, offline::TwinQ<float>& q,
                                                     offline::TwinQ<float>& q_target) {
  if (sc.algorithm == "td3") return std::make_unique<Td3Trainer<float>>(spec, policy, q, q_target, sc);
  return std::make_unique<SacTrainer<float>>(policy, q, q_target, sc);
}

}  // namespace masa::sac
