// How an actor turns observations into actions with the parameters the learner broadcasts: PPO's
// Gaussian around the policy mean (gaussian_behaviour.hpp), or SAC's and TD3's squashed policy
// (squashed_behaviour.hpp). The actor holds one, made for the run's `learner` by makeBehaviour,
// and never asks which.
#pragma once

#include <memory>
#include <vector>

#include "common/config/run_config.hpp"
#include "common/core/types.hpp"
#include "common/symmetry/symmetry_spec.hpp"

namespace masa::actor {

class Behaviour {
 public:
  virtual ~Behaviour() = default;
  // What a learner's message may carry: the policy's parameters, or the whole model's (a PPO
  // learner may send its critic too; the actor takes the policy prefix).
  virtual int policyParamCount() const = 0;
  virtual int modelParamCount() const { return policyParamCount(); }
  // Own initial parameters (start_without_learner), deterministic for the generator's state.
  virtual void initialize(Rng& rng) = 0;
  // The parameters of a checked message (`count` of them: the policy prefix is taken) and its
  // observation normalizer (null: the message has none).
  virtual void set(const float* params, int count, const float* mean, const float* std) = 0;
  // The rollout's log-std field: PPO's tied log-std; 0 for a policy whose std depends on the state.
  virtual void logStd(Eigen::VectorXf& out) const = 0;
  // Actions for E environments (obs_dim x E, raw): environment e's noise from rngs[e], drawn before
  // it steps, so the actions do not depend on the thread count. Writes the actions, the mean
  // (act_dim x E) and log pi of each action.
  virtual void act(const ConstMatRef<float>& obs, std::vector<Rng>& rngs, MatRef<float> actions, MatRef<float> mean,
                   float* log_prob) = 0;
};

// `learner: off_policy` -> SquashedBehaviour, otherwise GaussianBehaviour.
std::unique_ptr<Behaviour> makeBehaviour(const config::RunConfig& rc, const sym::SymmetrySpec& spec);

}  // namespace masa::actor
