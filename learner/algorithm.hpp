// What the Learner needs of a learning algorithm (rsl_rl's runner/algorithm split): the Learner
// keeps the intake, the rounds, parameter delivery, evaluation, metrics and checkpoints, whatever
// learns; the algorithm learns from each batch and says what its policy is. PPO
// (learner/ppo_algorithm.hpp) and SAC or TD3 on a replay (learner/sac/off_policy_rule.hpp) are
// its implementations; the program picks one for the run's `learner` key
// (learner/algorithms/algorithm_catalog.hpp) and hands it to the Learner.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "common/core/types.hpp"
#include "common/integrity/sealed_file.hpp"
#include "common/model/actor_critic.hpp"
#include "common/rollout/rollout_buffer.hpp"
#include "masa/lcmt_policy_params.hpp"

namespace masa::learner {

// metrics.csv's algorithm columns and the stats message's (PPO named them first): an algorithm
// fills what it has and leaves the rest 0.
struct LearnFigures {
  double actor_loss = 0, critic_loss = 0, entropy = 0, bounds_loss = 0;
  double sym_policy_loss = 0, sym_value_loss = 0;
  double kl = 0, lr = 0, grad_norm = 0, explained_variance = 0;
};

// A state too large for checkpoint.bin, streamed to its own sealed file beside it (the replay).
struct SideStateFile {
  std::string name;        // in the run directory, e.g. "off_policy_state.bin"
  integrity::FileKind kind;
};

class Algorithm {
 public:
  virtual ~Algorithm() = default;
  // The run config's `learner` value this algorithm runs ("ppo", "off_policy"): recorded in
  // checkpoint.bin, so a run is never resumed by another algorithm.
  virtual std::string kind() const = 0;
  // Learns from this rank's batch (the rounds' collectives inside, for data-parallel ranks).
  // env_streams names each environment column's source, the same id for the same actor's
  // environment every round (an episode's stretches are then known as one).
  virtual LearnFigures learn(rollout::RolloutBuffer& batch, std::span<const int64_t> env_streams, Rng& rng) = 0;
  // The last learn()'s part of the progress line.
  virtual std::string progressFigures(const LearnFigures& figures) const = 0;
  // A table of one row per round beside metrics.csv, with every figure the algorithm has (its
  // file name, e.g. "off_policy.csv"; empty: none), and the last round's figures by name.
  virtual std::string roundTable() const { return ""; }
  virtual std::vector<std::pair<std::string, double>> roundFigures() const { return {}; }
  // The learning curve's script: PPO's panels, or the replay's (learning_curve.hpp).
  virtual std::string curveScript(const std::string& title, const std::vector<std::string>& term_names,
                                  bool has_success) const = 0;
  // Whether every panel of the curve has a point (an off-policy run has no mean Q before its first
  // gradient step, and gnuplot stops at a panel without one).
  virtual bool curveHasData() const { return true; }

  // The parameters and normalizer the actors act with.
  virtual void fillPolicyMessage(masa::lcmt_policy_params& m) const = 0;
  // The policy the evaluator runs (its mean).
  virtual model::ActorCritic<float>& evaluationModel() = 0;
  // What inference needs (masa_eval, masa_deploy, masa_export).
  virtual void savePolicyFile(const std::string& path) const = 0;
  // A line on the policy's matrix kernels, for the end of a run ("" : nothing to say).
  virtual std::string kernelSummary() const { return ""; }

  // checkpoint.bin's part after the learner's counters, and back (the same bytes on every rank).
  virtual void saveCheckpointBody(std::ostream& os) const = 0;
  virtual void loadCheckpointBody(std::istream& is, const std::string& source) = 0;
  // The streamed state beside checkpoint.bin, if the algorithm has one.
  virtual std::optional<SideStateFile> sideState() const { return std::nullopt; }
  virtual void saveSideState(std::ostream&) const {}
  virtual void loadSideState(std::istream&, const std::string&) {}

  // Data-parallel ranks: whether the algorithm runs on several, and a hash of what every rank
  // must hold alike after an update (parameters, normalizers, learning rate).
  virtual bool dataParallel() const { return false; }
  virtual uint64_t agreementHash() const { return 0; }
};

}  // namespace masa::learner
