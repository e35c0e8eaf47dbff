// The PPO minibatch loss in rl_games' form, with its gradients w.r.t. the policy mean, the log-std
// and the critic output (the inputs of ActorCritic::backward):
//   ratio  = exp(logp - old_logp)
//   actor  = mean_b max(-A ratio, -A clip(ratio, 1 - e, 1 + e))
//   critic = mean_b max((v - R)^2, (v_clip - R)^2),  v_clip = old_v + clip(v - old_v, -e, e)
//            (plain mean (v - R)^2 without clip_value); v, old_v, R in the critic's units
//   bounds = mean_b sum_d max(mu - soft_bound, 0)^2 + min(mu + soft_bound, 0)^2
//   total  = actor + 0.5 critic_coef critic - entropy_coef entropy + bounds_coef bounds
// Also reported: KL(old || new) averaged over the batch and the fraction of clipped ratios.
#pragma once

#include "common/core/types.hpp"

namespace masa::ppo {

struct PpoLossConfig {
  double e_clip = 0.2;
  double entropy_coef = 0.0;
  double critic_coef = 4.0;
  double bounds_loss_coef = 1e-4;
  double soft_bound = 1.1;
  bool clip_value = true;
};

struct PpoLossStats {
  double actor_loss = 0, critic_loss = 0, entropy = 0, bounds_loss = 0, total_loss = 0;
  double kl = 0;             // mean over the batch of KL(old || new)
  double clip_fraction = 0;  // fraction of samples with |ratio - 1| > e_clip
};

// One minibatch, B samples as columns.
template <typename S>
struct PpoLossBatch {
  ConstMatRef<S> mean;          // act x B, current policy
  ConstVecRef<S> log_std;       // act, current policy
  ConstMatRef<S> value;         // 1 x B, current critic
  ConstMatRef<S> actions;       // act x B
  ConstMatRef<S> old_log_prob;  // 1 x B, behaviour policy
  ConstMatRef<S> old_mean;      // act x B, behaviour policy
  ConstMatRef<S> old_log_std;   // act x 1 or act x B, behaviour policy (see gaussian::kl)
  ConstMatRef<S> advantages;    // 1 x B
  ConstMatRef<S> old_value;     // 1 x B, critic before the update (same units as value)
  ConstMatRef<S> returns;       // 1 x B (same units as value)
};

template <typename S>
class PpoLoss {
 public:
  // Scratch for batches of up to max_batch samples is allocated here, never in compute().
  PpoLoss(const PpoLossConfig& config, int act_dim, int max_batch);

  // Loss parts and the gradients of the total w.r.t. mean, log_std and value.
  PpoLossStats compute(const PpoLossBatch<S>& batch);

  auto dmean() const { return dmean_.leftCols(batch_); }    // act x B
  const Vec<S>& dlogStd() const { return dlog_std_; }        // act
  auto dvalue() const { return dvalue_.leftCols(batch_); }  // 1 x B

  const PpoLossConfig& config() const { return config_; }

 private:
  PpoLossConfig config_;
  int act_dim_, max_batch_;
  int batch_ = 0;
  Mat<S> log_prob_, dlog_prob_, kl_, dmean_, dvalue_;
  Vec<S> dlog_std_;
};

}  // namespace masa::ppo
