#include "actors/squashed_behaviour.hpp"

#include <algorithm>
#include <limits>
#include <random>

#include "common/model/squashed_gaussian.hpp"
#include "common/model/td3_noise.hpp"

namespace masa::actor {

SquashedBehaviour::SquashedBehaviour(const config::RunConfig& rc, const sym::SymmetrySpec& spec)
    : sc_(sac::readSacConfig(rc)), policy_(spec, sac::policyShape(rc, sc_)) {}

void SquashedBehaviour::initialize(Rng& rng) {
  policy_.initialize(rng);
  warming_up_ = true;
}

void SquashedBehaviour::set(const float* params, int count, const float* mean, const float* std) {
  auto& values = policy_.params().values();
  std::copy(params, params + std::min<int>(count, static_cast<int>(values.size())), values.data());
  warming_up_ = mean == nullptr;
  if (!warming_up_) {
    policy_.obsNormalizer().setMeanStd(mean, std);
    policy_.setNormalizes(true);
  }
}

void SquashedBehaviour::act(const ConstMatRef<float>& obs, std::vector<Rng>& rngs, MatRef<float> actions,
                            MatRef<float> mean, float* log_prob) {
  const int E = static_cast<int>(obs.cols()), A = static_cast<int>(actions.rows());
  if (warming_up_) {
    std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
    for (int e = 0; e < E; ++e)
      for (int k = 0; k < A; ++k) actions(k, e) = uniform(rngs[e]);
    mean.setZero();
    std::fill(log_prob, log_prob + E, 0.0f);
    return;
  }
  policy_.normalize(obs, obs_n_);
  policy_.forward(obs_n_);
  eps_.resize(A, E);
  for (int e = 0; e < E; ++e) sac::squashed_gaussian::drawNoise<float>(rngs[e], eps_.col(e));
  mean = policy_.mean();
  if (sc_.algorithm == "td3") {
    sac::td3::noisyActions<float>(policy_.mean(), eps_, static_cast<float>(sc_.td3_exploration_noise),
                                  std::numeric_limits<float>::infinity(), actions);
    std::fill(log_prob, log_prob + E, 0.0f);
    return;
  }
  logp_.resize(1, E);
  sac::squashed_gaussian::sample<float>(policy_.mean(), policy_.logStd(), eps_, actions, logp_);
  std::copy(logp_.data(), logp_.data() + E, log_prob);
}

}  // namespace masa::actor
