#include "learner/offline/iql_trainer.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "common/model/diag_gaussian.hpp"
#include "learner/offline/iql_losses.hpp"
#include "learner/offline/log_std_bounds.hpp"

namespace masa::offline {
template <typename S>
IqlTrainer<S>::IqlTrainer(model::ActorCritic<S>& model, TwinQ<S>& q, TwinQ<S>& q_target, const OfflineConfig& config,
                          double reward_scale)
    : model_(&model),
      q_(&q),
      q_target_(&q_target),
      config_(config),
      reward_scale_(static_cast<S>(reward_scale)),
      actor_net_(model.params(), config.learning_rate, 0, model.policyParamCount()),
      value_net_(model.params(), config.learning_rate, model.policyParamCount(), model.params().size()),
      q_net_(q.params(), config.learning_rate, &q_target.params()),
      log_std_(model.actDim()),
      dlog_std_(model.actDim()),
      dzero_log_std_(Vec<S>::Zero(model.actDim())) {}

template <typename S>
void IqlTrainer<S>::normalize(const ConstMatRef<S>& raw, Mat<S>& out) {
  out.resize(raw.rows(), raw.cols());
  if (model_->config().normalize_obs)
    model_->obsNormalizer().normalize(raw, out);
  else
    out = raw;
}

template <typename S>
void IqlTrainer<S>::targetQ(const TransitionBatch<S>& batch) {
  normalize(batch.obs, obs_n_);
  target_q_.resize(1, batch.size());
  q_target_->minQ(obs_n_, batch.actions, target_q_);
}

template <typename S>
S IqlTrainer<S>::valueLoss(const TransitionBatch<S>& batch) {
  const int b = batch.size();
  targetQ(batch);
  model_->forward(batch.obs);
  dvalue_.resize(1, b);
  const S loss = expectileLoss<S>(model_->value(), target_q_, static_cast<S>(config_.expectile), dvalue_);
  stats_.mean_q = static_cast<double>(target_q_.mean());
  stats_.mean_v = static_cast<double>(model_->value().mean());
  dzero_mean_.setZero(model_->actDim(), b);
  model_->params().zeroGrad();
  model_->backward(dzero_mean_, dzero_log_std_, dvalue_);
  return loss;
}

template <typename S>
S IqlTrainer<S>::actorLoss(const TransitionBatch<S>& batch) {
  const int b = batch.size();
  targetQ(batch);
  model_->forward(batch.obs);
  // The advantage only weighs the samples: no gradient flows into V or Q through it.
  adv_ = target_q_ - model_->value();
  weight_.resize(1, b);
  advantageWeights<S>(adv_, static_cast<S>(config_.beta), static_cast<S>(config_.max_weight), weight_);
  model_->logStd(log_std_);
  logp_.resize(1, b);
  model::gaussian::logProb<S>(model_->mean(), log_std_, batch.actions, logp_);
  const S loss = -(weight_.cwiseProduct(logp_)).sum() / S(b);
  dlogp_ = -weight_ / S(b);
  dmean_.resize(model_->actDim(), b);
  dlog_std_.setZero();
  model::gaussian::logProbBackward<S>(model_->mean(), log_std_, batch.actions, dlogp_, dmean_, dlog_std_);
  stats_.mean_advantage = static_cast<double>(adv_.mean());
  stats_.mean_weight = static_cast<double>(weight_.mean());
  dzero_value_.setZero(1, b);
  model_->params().zeroGrad();
  model_->backward(dmean_, dlog_std_, dzero_value_);
  return loss;
}

template <typename S>
S IqlTrainer<S>::qLoss(const TransitionBatch<S>& batch) {
  const int b = batch.size();
  // V(o') is the critic alone (no policy work); the target is a constant for Q.
  td_target_ = model_->criticValue(batch.next_obs);
  td_target_ = reward_scale_ * batch.rewards +
               static_cast<S>(config_.discount) * batch.not_terminal.cwiseProduct(td_target_);
  normalize(batch.obs, obs_n_);
  const auto q = q_->forward(obs_n_, batch.actions);
  dq_.resize(2, b);
  const S loss = tdLoss<S>(q, td_target_, dq_);
  q_->params().zeroGrad();
  q_->backward(dq_);
  return loss;
}

template <typename S>
IqlStats IqlTrainer<S>::step(const TransitionBatch<S>& batch) {
  stats_.value_loss = static_cast<double>(valueLoss(batch));
  value_net_.step();

  // optax's cosine_decay_schedule(lr, steps): lr (1 + cos(pi t / T)) / 2, reaching 0 at T.
  const double progress = std::min(1.0, static_cast<double>(steps_) / static_cast<double>(config_.steps));
  stats_.actor_lr = config_.learning_rate * 0.5 * (1.0 + std::cos(std::numbers::pi * progress));
  actor_net_.setLearningRate(stats_.actor_lr);
  stats_.actor_loss = static_cast<double>(actorLoss(batch));
  actor_net_.step();
  clampLogStd<S>(*model_, static_cast<S>(config_.log_std_min), static_cast<S>(config_.log_std_max));

  stats_.q_loss = static_cast<double>(qLoss(batch));
  q_net_.step();
  q_net_.updateTarget(static_cast<S>(config_.polyak));
  ++steps_;
  return stats_;
}

double rewardScaleForReturns(const dataset::TransitionDataset& data) {
  if (data.episodes.empty()) return 1.0;
  double lo = data.episodes.front().ret, hi = lo;
  for (const auto& e : data.episodes) {
    lo = std::min(lo, e.ret);
    hi = std::max(hi, e.ret);
  }
  return hi - lo > 1e-9 ? 1000.0 / (hi - lo) : 1.0;
}

template class IqlTrainer<float>;
template class IqlTrainer<double>;

}  // namespace masa::offline
