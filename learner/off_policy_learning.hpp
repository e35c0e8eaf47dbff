// What the Learner needs of an off-policy algorithm, when the run's `learner` is off_policy
// (learner/sac/off_policy_rule.hpp implements it with SAC or TD3; masa_learner and masa_train
// hand it in, since the algorithm sits above this library). The intake, the rounds, parameter
// delivery, metrics, evaluation and checkpoints stay the Learner's; what changes is the update:
// instead of PPO's passes over the batch, the batch's transitions join a replay buffer and the
// algorithm takes the gradient steps they are owed (sac.updates_per_step per transition), so the
// parameters are broadcast every K = updates_per_step x ppo.num_envs x ppo.horizon gradient steps
// and ppo.max_policy_lag bounds how many rounds an actor may run ahead, as for PPO.
#pragma once

#include <iosfwd>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "common/model/actor_critic.hpp"
#include "common/rollout/rollout.hpp"
#include "learner/ppo/ppo_trainer.hpp"
#include "masa/lcmt_policy_params.hpp"

namespace masa::learner {

class OffPolicyLearning {
 public:
  virtual ~OffPolicyLearning() = default;
  // Takes the batch's transitions into replay and makes the gradient steps owed. env_streams names
  // each environment column's source (the same id for the same actor's environment every round,
  // so that an episode's stretches are known as one; empty: every stretch its own). The figures
  // that have a PPO column go there (actor_loss, critic_loss: twin Q, entropy, sym_policy_loss; the
  // others 0); roundFigures() has them all.
  virtual ppo::PpoStats learn(const rollout::Rollout& batch, std::span<const int64_t> env_streams, Rng& rng) = 0;
  // The last learn()'s figures by name (the columns of the run's off_policy.csv): gradient steps of
  // the round and in all, replay size, the losses, alpha, mean Q.
  virtual std::vector<std::pair<std::string, double>> roundFigures() const = 0;
  // The parameters and normalizer actors act with (obs_dim 0 while warming up: actors then act
  // uniformly at random, actors/squashed_behaviour.hpp).
  virtual void fillPolicyMessage(masa::lcmt_policy_params& m) const = 0;
  // The deterministic policy tanh(mean) as an ActorCritic, for the evaluator.
  virtual std::unique_ptr<model::ActorCritic<float>> evaluationModel() const = 0;
  virtual void savePolicyFile(const std::string& path) const = 0;
  // Everything a resumed run needs (networks, optimizers, replay, normalizer), and back.
  virtual void save(std::ostream& os) const = 0;
  virtual void load(std::istream& is, const std::string& source_name) = 0;
  virtual long long gradientSteps() const = 0;
  virtual long long replaySize() const = 0;
};

}  // namespace masa::learner
