// How an actor of a PPO run acts: the policy half of the learner's model (no critic, no training
// caches: model::InferencePolicy) gives the mean, and each environment draws its action from the
// Gaussian around it with the tied log-std, keeping log pi for PPO's ratio.
#pragma once

#include <memory>

#include "actors/behaviour.hpp"
#include "common/model/inference_policy.hpp"

namespace masa::actor {

class GaussianBehaviour final : public Behaviour {
 public:
  GaussianBehaviour(const config::RunConfig& rc, const sym::SymmetrySpec& spec);

  int policyParamCount() const override { return static_cast<int>(policy_->params().size()); }
  int modelParamCount() const override { return model_param_count_; }
  // The policy's draws of ActorCritic::initialize: the learner's model prefix for the same state.
  void initialize(Rng& rng) override { policy_->initialize(rng); }
  void set(const float* params, int count, const float* mean, const float* std) override;
  void logStd(Eigen::VectorXf& out) const override { policy_->logStd(out); }
  void act(const ConstMatRef<float>& obs, std::vector<Rng>& rngs, MatRef<float> actions, MatRef<float> mean,
           float* log_prob) override;

  model::InferencePolicy<float>& policy() { return *policy_; }

 private:
  std::unique_ptr<model::InferencePolicy<float>> policy_;
  int model_param_count_ = 0;
};

}  // namespace masa::actor
