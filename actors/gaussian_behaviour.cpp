#include "actors/gaussian_behaviour.hpp"

#include <algorithm>

#include "common/model/actor_critic.hpp"
#include "common/model/diag_gaussian.hpp"

namespace masa::actor {

GaussianBehaviour::GaussianBehaviour(const config::RunConfig& rc, const sym::SymmetrySpec& spec)
    : policy_(std::make_unique<model::InferencePolicy<float>>(spec, rc.model)) {
  // A whole model only for its parameter count: the critic's shape is the learner's business.
  model_param_count_ = static_cast<int>(model::ActorCritic<float>(spec, rc.model).params().size());
}

void GaussianBehaviour::set(const float* params, int count, const float* mean, const float* std) {
  // The policy prefix (a whole model's critic part is not the actor's).
  auto& values = policy_->params().values();
  std::copy(params, params + std::min<int>(count, static_cast<int>(values.size())), values.data());
  if (mean) policy_->obsNormalizer().setMeanStd(mean, std);
}

void GaussianBehaviour::act(const ConstMatRef<float>& obs, std::vector<Rng>& rngs, MatRef<float> actions,
                            MatRef<float> mean, float* log_prob) {
  mean = policy_->actMean(obs);
  Eigen::VectorXf log_std(actions.rows());
  policy_->logStd(log_std);
  for (int e = 0; e < static_cast<int>(obs.cols()); ++e) {
    Eigen::Map<const Mat<float>> mu(mean.col(e).data(), actions.rows(), 1);
    Eigen::Map<Mat<float>> act(actions.col(e).data(), actions.rows(), 1);
    Eigen::Map<Mat<float>> lp(log_prob + e, 1, 1);
    model::gaussian::sample<float>(mu, log_std, rngs[e], act);
    model::gaussian::logProb<float>(mu, log_std, act, lp);
  }
}

}  // namespace masa::actor
