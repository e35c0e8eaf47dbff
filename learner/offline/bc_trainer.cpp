#include "learner/offline/bc_trainer.hpp"

#include "common/model/diag_gaussian.hpp"
#include "learner/offline/log_std_bounds.hpp"

namespace masa::offline {

template <typename S>
BcTrainer<S>::BcTrainer(model::ActorCritic<S>& model, const OfflineConfig& config)
    : model_(&model),
      config_(config),
      adam_(model.params(), nn::AdamConfig<S>{static_cast<S>(config.learning_rate)}, 0, model.policyParamCount()),
      log_std_(model.actDim()),
      dlog_std_(model.actDim()) {}

template <typename S>
S BcTrainer<S>::loss(const TransitionBatch<S>& batch) {
  const int b = batch.size(), a = model_->actDim();
  model_->forward(batch.obs);
  const auto mean = model_->mean();
  model_->logStd(log_std_);
  dmean_.resize(a, b);
  dvalue_.setZero(1, b);
  dlog_std_.setZero();
  S loss = S(0);
  if (config_.bc_loss == BcLoss::kGaussian) {
    logp_.resize(1, b);
    model::gaussian::logProb<S>(mean, log_std_, batch.actions, logp_);
    loss = -logp_.sum() / S(b);
    dlogp_.setConstant(1, b, S(-1) / S(b));
    model::gaussian::logProbBackward<S>(mean, log_std_, batch.actions, dlogp_, dmean_, dlog_std_);
  } else {
    dmean_ = mean - batch.actions;
    loss = dmean_.squaredNorm() / S(a * b);
    dmean_ *= S(2) / S(a * b);
  }
  model_->params().zeroGrad();
  model_->backward(dmean_, dlog_std_, dvalue_);
  return loss;
}

template <typename S>
BcStats BcTrainer<S>::step(const TransitionBatch<S>& batch) {
  BcStats s;
  s.loss = static_cast<double>(loss(batch));
  adam_.step();
  clampLogStd<S>(*model_, static_cast<S>(config_.log_std_min), static_cast<S>(config_.log_std_max));
  model_->logStd(log_std_);
  s.mean_log_std = static_cast<double>(log_std_.mean());
  return s;
}

template class BcTrainer<float>;
template class BcTrainer<double>;

}  // namespace masa::offline
