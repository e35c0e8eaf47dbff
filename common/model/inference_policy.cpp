#include "common/model/inference_policy.hpp"

#include "common/core/check.hpp"

namespace masa::model {

template <typename S>
InferencePolicy<S>::InferencePolicy(const sym::SymmetrySpec& spec, const ModelConfig& config)
    : spec_(spec),
      config_(config),
      maps_(buildAgentMaps(config.method, spec_)),
      // The names and the order of ActorCritic's constructor: the same layout as its prefix.
      policy_(params_, "policy", &maps_, config.policy_hidden, config.activation),
      log_std_(params_, "policy.log_std", logStdClasses(config.method, spec_)),
      obs_norm_(spec_.obsDim()) {
  params_.finalize();
  symmetrizeNormalizer(obs_norm_, config.method, spec_);
}

template <typename S>
std::unique_ptr<InferencePolicy<S>> InferencePolicy<S>::of(const ActorCritic<S>& model) {
  auto p = std::make_unique<InferencePolicy<S>>(model.spec(), model.config());
  MASA_CHECK(p->params_.size() == model.policyParamCount(),
             "inference policy: " << p->params_.size() << " parameters, the model's policy prefix "
                                  << model.policyParamCount());
  p->params_.values() = model.params().values().head(p->params_.size());
  p->obs_norm_ = model.obsNormalizer();
  return p;
}

template <typename S>
void InferencePolicy<S>::initialize(Rng& rng) {
  policy_.initialize(rng, static_cast<S>(config_.policy_last_layer_scale));
  log_std_.initialize(static_cast<S>(config_.init_log_std));
}

template <typename S>
Eigen::Map<const Mat<S>> InferencePolicy<S>::actMean(const ConstMatRef<S>& raw_obs) {
  MASA_CHECK(raw_obs.rows() == obsDim(), "observation has " << raw_obs.rows() << " rows, expected " << obsDim());
  const Eigen::Index b = raw_obs.cols();
  if (obs_normalized_.cols() < b) obs_normalized_.resize(obsDim(), b);
  if (config_.normalize_obs) obs_norm_.normalize(raw_obs, obs_normalized_.leftCols(b));
  else obs_normalized_.leftCols(b) = raw_obs;
  auto action = policy_.infer(obs_normalized_.leftCols(b));
  if (config_.squash == ActionSquash::kTanh) action.array() = action.array().tanh();
  return Eigen::Map<const Mat<S>>(action.data(), actDim(), b);
}

template class InferencePolicy<float>;
template class InferencePolicy<double>;

}  // namespace masa::model
