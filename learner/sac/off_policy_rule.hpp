// SAC or TD3 (sac.algorithm) as the Learner's algorithm for `learner: off_policy`
// (learner/algorithm.hpp): the distributed form of masa_sac, fed by actors over LCM. The batch's
// transitions join a replay buffer and the algorithm takes the gradient steps they are owed
// (sac.updates_per_step per transition), so the parameters are broadcast every K =
// updates_per_step x ppo.num_envs x ppo.horizon gradient steps and ppo.max_policy_lag bounds how
// many rounds an actor may run ahead, as for PPO. Its replay and networks are streamed to
// off_policy_state.bin beside the checkpoint; off_policy.csv has a row of figures per round.
//
// Each round's batch (E environments x T steps, step-major) goes into the replay buffer
// environment by environment, in time order, so that every stored stretch is one environment's
// consecutive steps: the next observation is the next step's (a time-out's own pre-reset
// observation at a truncation), and the stretch's last step is stored as cut, which is what a
// time-out is to an n-step return: stop there and bootstrap from that step's next observation.
// A stretch never runs on into another environment's steps.
//
// Warm-up: until sac.learning_starts transitions arrived the actors act uniformly at random (the
// parameters go out without a normalizer); then the normalizer is fitted on them and fixed, as in
// masa_sac, and the gradient steps start: floor(updates_per_step x transitions past the start).
//
// Episodes: a stretch continues its stream's episode when it starts from the observation the
// stream's last stretch ended on (the same actor's environment, nothing dropped between), so that
// hindsight relabeling (sac.her_share) draws goals from the whole episode across rounds.
#pragma once

#include <algorithm>
#include <map>
#include <memory>
#include <vector>

#include "common/config/run_config.hpp"
#include "common/config/sac_config.hpp"
#include "common/model/sac_policy.hpp"
#include "learner/algorithm.hpp"
#include "learner/offline/twin_q.hpp"
#include "learner/sac/off_policy_trainer.hpp"
#include "learner/sac/hindsight.hpp"
#include "learner/sac/replay_buffer.hpp"

namespace masa::sac {

class OffPolicyRule final : public learner::Algorithm {
 public:
  // Initializes the networks from rng (the learner's generator, seeded by the run).
  OffPolicyRule(const config::RunConfig& rc, Rng& rng);
  ~OffPolicyRule() override;

  std::string kind() const override { return "off_policy"; }
  // Takes the batch's transitions into replay and makes the gradient steps owed. The figures that
  // have a metrics.csv column go there (actor_loss, critic_loss: twin Q, entropy, sym_policy_loss;
  // the others 0); roundFigures() has them all.
  learner::LearnFigures learn(rollout::RolloutBuffer& batch, std::span<const int64_t> env_streams, Rng& rng) override;
  learner::LearnFigures learn(const rollout::Rollout& batch, std::span<const int64_t> env_streams, Rng& rng);
  // Its gradient steps, twin-Q loss, temperature, entropy and mean Q, or that it still acts at random.
  std::string progressFigures(const learner::LearnFigures& figures) const override;
  std::string roundTable() const override { return "off_policy.csv"; }
  // Gradient steps of the round and in all, replay size, the losses, alpha, mean Q.
  std::vector<std::pair<std::string, double>> roundFigures() const override;
  std::string curveScript(const std::string& title, const std::vector<std::string>& term_names,
                          bool has_success) const override;
  bool curveHasData() const override { return trainer_->steps() > 0; }
  // The actors act uniformly at random while the message has no normalizer (obs_dim 0: warming up,
  // actors/squashed_behaviour.hpp).
  void fillPolicyMessage(masa::lcmt_policy_params& m) const override;
  // The deterministic policy tanh(mean) as an ActorCritic, for the evaluator.
  model::ActorCritic<float>& evaluationModel() override;
  void savePolicyFile(const std::string& path) const override;
  // Nothing in checkpoint.bin: everything is in the side state.
  void saveCheckpointBody(std::ostream&) const override {}
  void loadCheckpointBody(std::istream& is, const std::string& source) override;
  std::optional<learner::SideStateFile> sideState() const override;
  void saveSideState(std::ostream& os) const override { save(os); }
  void loadSideState(std::istream& is, const std::string& source) override { load(is, source); }

  // Everything a resumed run needs (networks, optimizers, replay, normalizer, streams), and back.
  void save(std::ostream& os) const;
  void load(std::istream& is, const std::string& source_name);
  long long gradientSteps() const { return trainer_->steps(); }
  int roundGradientSteps() const { return round_steps_; }  // the last learn()'s
  long long replaySize() const { return replay_.size(); }

  long long transitionsReceived() const { return received_; }
  bool warmingUp() const { return !fitted_; }
  const ReplayBuffer& replay() const { return replay_; }
  SacPolicy<float>& policy() { return policy_; }

 private:
  void fitNormalizer();
  void applyNormalizer();
  // Resumed from a state that kept fewer transitions than learning_starts: filling up again.
  bool refilling() const { return fitted_ && replay_.size() < std::min(sc_.learning_starts, sc_.buffer_size); }

  config::RunConfig rc_;
  SacConfig sc_;
  sym::SymmetrySpec spec_;
  SacPolicy<float> policy_;
  offline::TwinQ<float> q_, q_target_;
  std::unique_ptr<OffPolicyTrainer<float>> trainer_;
  ReplayBuffer replay_;
  std::unique_ptr<Hindsight> hindsight_;
  // Each stream's episode and the observation its last stretch ended on; the next episode id.
  struct StreamTail {
    long long episode = 0;
    std::vector<float> last_obs;
  };
  std::map<int64_t, StreamTail> streams_;
  long long next_episode_ = 0;
  long long received_ = 0;  // transitions taken into replay since the run began
  long long forgiven_ = 0;  // gradient steps not owed: the rounds a compact state's replay refilled
  bool fitted_ = false;     // the normalizer is fitted: learning has started
  // The fitted normalizer as the actors are sent it (kept: a reloaded normalizer would re-derive it).
  std::vector<float> norm_mean_, norm_std_;
  ReplayBatch<float> batch_;
  std::unique_ptr<model::ActorCritic<float>> evaluation_model_;  // evaluationModel()'s, rebuilt per call
  SacStats round_means_;  // of the last learn()'s gradient steps
  int round_steps_ = 0;
  double round_relabeled_share_ = 0;
};

// An off-policy round's part of the progress line, from its figures (roundFigures()).
std::string offPolicyProgressFigures(const std::vector<std::pair<std::string, double>>& figures);

}  // namespace masa::sac
