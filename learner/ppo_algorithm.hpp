// PPO as the Learner's algorithm (learner/algorithm.hpp): the actor-critic, its Adam and the
// trainer's passes over each batch; the policy prefix of the parameters goes to the actors.
// Data-parallel: every rank holds the same networks and averages its gradients with the others'.
#pragma once

#include <memory>

#include "common/cluster/communicator.hpp"
#include "common/config/run_config.hpp"
#include "common/nn/adam.hpp"
#include "learner/algorithm.hpp"
#include "learner/ppo/ppo_trainer.hpp"

namespace masa::learner {

class PpoAlgorithm final : public Algorithm {
 public:
  // Initializes the networks from rng (the learner's generator, seeded by the run).
  PpoAlgorithm(const config::RunConfig& rc, Rng& rng, cluster::Communicator& ranks);

  std::string kind() const override { return "ppo"; }
  LearnFigures learn(rollout::RolloutBuffer& batch, std::span<const int64_t> env_streams, Rng& rng) override;
  std::string progressFigures(const LearnFigures& figures) const override;
  std::string curveScript(const std::string& title, const std::vector<std::string>& term_names,
                          bool has_success) const override;
  void fillPolicyMessage(masa::lcmt_policy_params& m) const override;
  model::ActorCritic<float>& evaluationModel() override { return *model_; }
  void savePolicyFile(const std::string& path) const override;
  std::string kernelSummary() const override { return model_->chunkWidthSummary(); }
  // lr, the minibatch shuffle, the model with its normalizers, Adam's moments.
  void saveCheckpointBody(std::ostream& os) const override;
  void loadCheckpointBody(std::istream& is, const std::string& source) override;
  bool dataParallel() const override { return true; }
  uint64_t agreementHash() const override;

  const model::ActorCritic<float>& model() const { return *model_; }

 private:
  config::RunConfig rc_;
  std::unique_ptr<model::ActorCritic<float>> model_;
  std::unique_ptr<nn::Adam<float>> adam_;
  std::unique_ptr<ppo::PpoTrainer> trainer_;
  std::vector<int> restored_order_;  // the shuffle from a checkpoint, used by the first update
};

// The model of a PPO run's checkpoint.bin, for evaluating it directly (masa_eval); the checkpoint of
// another algorithm's run holds none, and the refusal says to evaluate its policy.bin.
void loadPpoCheckpointModel(const std::string& path, model::ActorCritic<float>& model);

// For LearnerOptions::make_algorithm where a program runs PPO alone (tests, benchmarks).
std::unique_ptr<Algorithm> makePpoAlgorithm(const config::RunConfig& rc, Rng& rng, cluster::Communicator& ranks);

}  // namespace masa::learner
