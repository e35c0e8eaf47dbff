// TD3 (Fujimoto et al. 2018, "Addressing Function Approximation Error in Actor-Critic Methods")
// on the SAC policy network's mean half: the deterministic policy tanh(mean(o)) (the log-std half
// is not used, and trained by nothing but SASA's symmetry loss), a target copy of it, and the
// twin Q. One gradient step on a replay batch:
//   1. critic: both Q_k(o, a) towards R + discount min Q'(o', a'), where a' is the target policy
//      smoothed: clip(tanh(mean'(o')) + clip(sigma eps, -c, c), -1, 1) (td3_noise.hpp)
//   2. every sac.td3_policy_delay critic steps (delayed actor): the actor L = -mean Q_1(o,
//      tanh(mean(o))) through the Q just updated, then both targets move by Polyak.
// Collection: clip(tanh(mean) + sac.td3_exploration_noise eps, -1, 1). The noise comes from the
// generator passed in. For MASA the mean is equivariant and Q_1, Q' invariant under (T_i o, T_i a),
// so the actor loss is invariant and every noisy action equivariant (with the noise T_i eps). The
// policy file (sac_policy_file.hpp) is SAC's: tanh(mean).
#pragma once

#include <iosfwd>

#include "common/nn/optimized_net.hpp"
#include "learner/offline/twin_q.hpp"
#include "learner/sac/off_policy_trainer.hpp"
#include "common/config/sac_config.hpp"
#include "common/model/sac_policy.hpp"

namespace masa::sac {

template <typename S>
class Td3Trainer : public OffPolicyTrainer<S> {
 public:
  // The target policy starts as a copy of `policy`; q_target is the caller's (as for SAC).
  Td3Trainer(const sym::SymmetrySpec& spec, SacPolicy<S>& policy, offline::TwinQ<S>& q, offline::TwinQ<S>& q_target,
             const SacConfig& config);

  void explore(const ConstMatRef<S>& raw_obs, Rng& rng, MatRef<S> actions) override;
  SacStats step(const ReplayBatch<S>& batch, Rng& rng) override;
  long long steps() const override { return steps_; }

  // The losses of steps 1 and 2 as they would be now, each leaving its gradients in the parameters
  // it trains (zeroed first): q's, the policy's. No step is taken.
  S criticLoss(const ReplayBatch<S>& batch, Rng& rng);
  S actorLoss(const ReplayBatch<S>& batch);
  const SacPolicy<S>& targetPolicy() const { return policy_target_; }

  // The policy and its target, Q, Q', both Adams and the step count.
  void save(std::ostream& os) const override;
  void load(std::istream& is) override;

 private:
  SacPolicy<S>* policy_;
  SacPolicy<S> policy_target_;
  offline::TwinQ<S>* q_;
  offline::TwinQ<S>* q_target_;
  SacConfig config_;
  nn::OptimizedNet<S> policy_net_, q_net_;  // with their targets policy_target_, q_target
  long long steps_ = 0;
  SacStats stats_;

  Mat<S> obs_n_, next_n_, eps_, act_, min_q_, target_, dq_, dq1_, da_, dmean_, dlog_std_;
};

}  // namespace masa::sac
