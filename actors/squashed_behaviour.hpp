// How an actor of an off-policy run (learner: off_policy) acts: with the SAC policy the learner
// broadcasts (common/model/sac_policy.hpp), SAC's sample tanh(mean + std eps) or TD3's
// tanh(mean) + sigma eps (sac.algorithm), and uniformly at random while the learner warms up.
//
// The warm-up is said by the parameters themselves: the off-policy learner broadcasts them
// without an observation normalizer (lcmt_policy_params.obs_dim = 0) until sac.learning_starts
// transitions arrived and it fitted one; after that every message carries it (the identity when
// model.normalize_obs is off). Each environment's noise comes from its own generator, drawn in
// environment order, so the actions do not depend on the thread count.
#pragma once

#include <memory>
#include <vector>

#include "actors/behaviour.hpp"
#include "common/config/run_config.hpp"
#include "common/config/sac_config.hpp"
#include "common/model/sac_policy.hpp"

namespace masa::actor {

class SquashedBehaviour final : public Behaviour {
 public:
  SquashedBehaviour(const config::RunConfig& rc, const sym::SymmetrySpec& spec);

  int policyParamCount() const override { return static_cast<int>(policy_.params().size()); }
  // Own initial parameters (start_without_learner): warming up, so uniform actions.
  void initialize(Rng& rng) override;
  // Parameters of a checked message; `mean`/`std` null: no normalizer yet, the learner warms up.
  void set(const float* params, int count, const float* mean, const float* std) override;
  bool warmingUp() const { return warming_up_; }
  // SAC's std depends on the state: the rollout's log-std field (PPO's) is 0.
  void logStd(Eigen::VectorXf& out) const override { out.setZero(); }

  // The pre-squash mean, and log pi of each action (SAC; TD3's deterministic policy has none: 0).
  // During the warm-up: uniform in [-1, 1], mean 0.
  void act(const ConstMatRef<float>& obs, std::vector<Rng>& rngs, MatRef<float> actions, MatRef<float> mean,
           float* log_prob) override;

 private:
  sac::SacConfig sc_;
  sac::SacPolicy<float> policy_;
  bool warming_up_ = true;
  Mat<float> obs_n_, eps_, logp_;
};

}  // namespace masa::actor
