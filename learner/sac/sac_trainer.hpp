// Soft Actor-Critic (Haarnoja et al. 2018) with automatic entropy temperature on our networks. One
// gradient step on a replay batch, in the order of the reference implementations (SB3, CleanRL):
//   1. critic: both Q_k(o, a) towards R + discount (min Q'(o', a') - alpha log pi(a' | o')),
//      a' ~ pi(o') (sac_losses.hpp: softQTarget, twinQLoss; R, discount: n-step, replay_buffer.hpp)
//   2. actor:  mean(alpha log pi(a | o) - min Q(o, a)), a ~ pi(o) reparameterized through the
//      Q just updated
//   3. temperature: -alpha mean(log pi + target_entropy) on step 2's log-probs (if autotuned)
//   4. Q' <- Q' + polyak (Q - Q')
// The noise of steps 1 and 2 is drawn from the generator passed to step(). Observations are
// normalized by the policy's (fixed) normalizer for the policy and both Qs; actions are the
// squashed ones in [-1, 1]. For MASA the policy is equivariant and Q, Q' are invariant under
// (T_i o, T_i a), so every target and loss is too.
#pragma once

#include <iosfwd>

#include "common/nn/optimized_net.hpp"
#include "learner/offline/twin_q.hpp"
#include "learner/sac/off_policy_trainer.hpp"
#include "learner/sac/replay_buffer.hpp"
#include "common/config/sac_config.hpp"
#include "common/model/sac_policy.hpp"

namespace masa::sac {

template <typename S>
class SacTrainer : public OffPolicyTrainer<S> {
 public:
  SacTrainer(SacPolicy<S>& policy, offline::TwinQ<S>& q, offline::TwinQ<S>& q_target, const SacConfig& config);

  // A sample of the squashed Gaussian (SacPolicy::actStochastic).
  void explore(const ConstMatRef<S>& raw_obs, Rng& rng, MatRef<S> actions) override {
    policy_->actStochastic(raw_obs, rng, actions);
  }
  SacStats step(const ReplayBatch<S>& batch, Rng& rng) override;
  long long steps() const override { return steps_; }
  S logAlpha() const { return log_alpha_.values()(0); }
  double alpha() const;
  double targetEntropy() const { return target_entropy_; }

  // The losses of steps 1-3 as they would be now, each leaving its gradients in the parameters it
  // trains (zeroed first): q's, the policy's, log alpha's. No step is taken. temperatureLoss uses
  // the log-probs of the last actorLoss.
  S criticLoss(const ReplayBatch<S>& batch, Rng& rng);
  S actorLoss(const ReplayBatch<S>& batch, Rng& rng);
  S temperatureLoss();

  // Everything a resumed run needs to take the same next step: the policy (with its normalizer),
  // Q, Q', log alpha, the three Adams and the step count. The replay buffer and the generators are
  // the caller's.
  void save(std::ostream& os) const override;
  void load(std::istream& is) override;

 private:
  SacPolicy<S>* policy_;
  offline::TwinQ<S>* q_;
  offline::TwinQ<S>* q_target_;
  SacConfig config_;
  double target_entropy_;
  nn::ParameterSet<S> log_alpha_;
  nn::OptimizedNet<S> policy_net_, q_net_, alpha_net_;  // q_net_ moves q_target
  long long steps_ = 0;
  SacStats stats_;

  Mat<S> obs_n_, next_n_, eps_, act_, logp_, min_q_, target_, dq_, dlogp_, da_, dmean_, dlog_std_;
};

}  // namespace masa::sac
