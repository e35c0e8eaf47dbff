// Behaviour cloning of an ActorCritic's policy: maximum likelihood of the dataset's actions under
// the diagonal Gaussian (mean from the network, learned state-independent log-std), or the mean
// squared error of the mean alone. Adam on the policy's parameters only; the critic is untouched.
// The method is the model's: SA, SA on augmented data (SASA-data), or MASA (equivariant policy).
#pragma once

#include "common/model/actor_critic.hpp"
#include "common/nn/adam.hpp"
#include "learner/offline/offline_config.hpp"
#include "learner/offline/transition_batch.hpp"

namespace masa::offline {

struct BcStats {
  double loss = 0;          // negative log-likelihood per sample, or MSE per action entry
  double mean_log_std = 0;  // over action dimensions, after the step
};

template <typename S>
class BcTrainer {
 public:
  BcTrainer(model::ActorCritic<S>& model, const OfflineConfig& config);

  // Loss of the batch with its gradients in model.params().grads() (zeroed first); no step.
  S loss(const TransitionBatch<S>& batch);
  // One gradient step on the batch.
  BcStats step(const TransitionBatch<S>& batch);

 private:
  model::ActorCritic<S>* model_;
  OfflineConfig config_;
  nn::Adam<S> adam_;
  Mat<S> logp_, dlogp_, dmean_, dvalue_;
  Vec<S> log_std_, dlog_std_;
};

}  // namespace masa::offline
