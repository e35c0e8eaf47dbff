// Implicit Q-Learning (Kostrikov, Nair, Levine 2021) on our networks, in the update order of the
// original code:
//   1. V:     expectile regression of V(o) towards min(Q1', Q2')(o, a) of the target networks
//   2. actor: advantage-weighted log-likelihood, weights min(exp(beta (Q'(o,a) - V(o))), max_weight)
//             with the V of step 1; the actor's learning rate decays by a cosine over the run
//   3. Q:     both Q_k(o, a) towards reward_scale r + discount (1 - terminal) V(o')
//   4. target Q' moves towards Q by the Polyak rate
// Policy and V are one ActorCritic (policy = its actor, V = its critic, both saved in policy.bin):
// for MASA an equivariant policy and an invariant V. Q is a TwinQ of the same method (symmetric
// under the joint transform for MASA). Q sees the model's normalized observations.
#pragma once

#include "common/model/actor_critic.hpp"
#include "common/nn/optimized_net.hpp"
#include "learner/offline/offline_config.hpp"
#include "learner/offline/transition_batch.hpp"
#include "learner/offline/twin_q.hpp"

namespace masa::offline {

struct IqlStats {
  double value_loss = 0, actor_loss = 0, q_loss = 0;
  double mean_q = 0, mean_v = 0, mean_advantage = 0, mean_weight = 0;
  double actor_lr = 0;
};

template <typename S>
class IqlTrainer {
 public:
  // reward_scale multiplies the dataset's rewards in the TD target (rewardScale() below).
  IqlTrainer(model::ActorCritic<S>& model, TwinQ<S>& q, TwinQ<S>& q_target, const OfflineConfig& config,
             double reward_scale = 1.0);

  // One step of 1-4 on one batch.
  IqlStats step(const TransitionBatch<S>& batch);
  long long steps() const { return steps_; }

  // The losses of steps 1-3 as they would be now, each leaving its gradients in the parameter set
  // it trains (zeroed first): model's critic range, model's policy range, q's. No step is taken.
  S valueLoss(const TransitionBatch<S>& batch);
  S actorLoss(const TransitionBatch<S>& batch);
  S qLoss(const TransitionBatch<S>& batch);

 private:
  void normalize(const ConstMatRef<S>& raw, Mat<S>& out);
  void targetQ(const TransitionBatch<S>& batch);

  model::ActorCritic<S>* model_;
  TwinQ<S>* q_;
  TwinQ<S>* q_target_;
  OfflineConfig config_;
  S reward_scale_;
  nn::OptimizedNet<S> actor_net_, value_net_, q_net_;  // q_net_ moves q_target
  long long steps_ = 0;
  IqlStats stats_;  // figures of the losses last computed

  Mat<S> obs_n_, target_q_, adv_, weight_, logp_, dlogp_, dmean_, dzero_mean_, dvalue_, dzero_value_, td_target_, dq_;
  Vec<S> log_std_, dlog_std_, dzero_log_std_;
};

// IQL's scaling of rewards for locomotion data: 1000 / (max - min) over the dataset's episode
// returns, so that beta means the same on every task. 1 when the returns do not differ.
double rewardScaleForReturns(const dataset::TransitionDataset& data);

}  // namespace masa::offline
