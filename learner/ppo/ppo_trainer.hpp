// One PPO update of an ActorCritic<float> from a full RolloutBuffer (rl_games' a2c_continuous
// arrangement):
//   prepare():  1. obs normalizer += the batch's observations (actors only read it; the learner
//                  owns it and moves it once per batch, before anything is evaluated with it)
//               2. critic values of the batch, the bootstrap and the time-outs' final observations,
//                  denormalized to real units with the value normalizer as it was at collection
//               3. GAE in real units; returns = advantages + values
//               4. value normalizer += returns; old values and returns renormalized with it, so the
//                  clipped value loss compares like with like
//               5. advantages normalized by their batch mean and (unbiased) std
//   optimize(): mini_epochs x shuffled minibatches: forward, loss, backward, grad-norm clip, Adam
//               step, then the adaptive lr from that minibatch's KL(previous visit || new),
//               measured before the step as rl_games does: the drift of one mini-epoch, not of
//               all mini-epochs since collection. Allocates nothing once the sizes have been seen.
// update() = prepare() + optimize().
//
// Data-parallel (a Communicator of N learner ranks): each rank holds its share of the batch (its
// actors' environments), and together they make the update one learner would make on the whole
// batch, the ranks' environments side by side in rank order. The normalizers' moments, the batch
// statistics and the advantages' mean and variance are summed across ranks; every rank draws the
// same permutation of the whole batch, and each minibatch's gradient is the sum over ranks of each
// rank's gradient on its part of that minibatch weighted by its share of the samples (every loss
// term is a mean over samples), summed as one flat buffer; the loss statistics (the KL that drives
// the learning rate among them) likewise. Every rank then clips and steps the same gradient. Equal
// to one learner up to the order of floating-point sums (tests/mpi/: 1e-5 relative after 3 updates).
// With one rank nothing is summed or scaled: the update is bit for bit the single learner's.
#pragma once

#include <vector>

#include "common/cluster/communicator.hpp"
#include "common/config/run_config.hpp"
#include "common/model/actor_critic.hpp"
#include "common/nn/adam.hpp"
#include "learner/ppo/adaptive_lr.hpp"
#include "learner/ppo/gae.hpp"
#include "learner/ppo/ppo_loss.hpp"
#include "common/rollout/rollout_buffer.hpp"

namespace masa::ppo {

struct PpoStats {
  // Means over the update's minibatches.
  double actor_loss = 0, critic_loss = 0, entropy = 0, bounds_loss = 0, total_loss = 0;
  double sym_policy_loss = 0, sym_value_loss = 0;  // SASA only (already weighted)
  double kl = 0, clip_fraction = 0;
  double grad_norm = 0;  // before clipping
  // After the update.
  double lr = 0;
  // Of the batch, before the update, in real units.
  double explained_variance = 0;  // 1 - Var(R - V) / Var(R)
  double mean_value = 0, mean_return = 0, mean_advantage = 0;
  int minibatches = 0;
};

class PpoTrainer {
 public:
  PpoTrainer(model::ActorCritic<float>& model, nn::Adam<float>& adam, const config::PpoConfig& config,
             cluster::Communicator& ranks = cluster::soloCommunicator());

  PpoStats update(RolloutBuffer& buffer, Rng& rng);

  // The two halves of update(), separately callable (e.g. to measure the minibatch loop alone).
  void prepare(RolloutBuffer& buffer);
  PpoStats optimize(const RolloutBuffer& buffer, Rng& rng);

  AdaptiveLr& learningRate() { return lr_; }
  const AdaptiveLr& learningRate() const { return lr_; }
  const config::PpoConfig& config() const { return config_; }
  // The minibatch shuffle carries over between updates (each shuffles the last permutation), so a
  // checkpoint must hold it for a resumed run to repeat the same minibatches. Sized by prepare() to
  // the whole batch (of every rank), the same on every rank.
  std::vector<int>& shuffleOrder() { return order_; }
  const std::vector<int>& shuffleOrder() const { return order_; }

 private:
  void resizeForBatch(const RolloutBuffer& buffer);
  // Sums x[0..n) across ranks (nothing with one rank).
  void sumAcrossRanks(double* x, int n) { if (ranks_->size() > 1) ranks_->sum(x, n); }
  // Critic values (normalized units) of obs columns, in chunks of at most minibatch_size.
  void evaluateValues(const ConstMatRef<float>& obs, float* out);

  cluster::Communicator* ranks_;
  model::ActorCritic<float>* model_;
  nn::Adam<float>* adam_;
  config::PpoConfig config_;
  GaeConfig gae_;
  PpoLoss<float> loss_;
  AdaptiveLr lr_;
  PpoStats prepared_;  // the batch statistics of the last prepare()

  // The whole batch across ranks: E = sum of every rank's environments, this rank's from env_offset_.
  int64_t global_size_ = 0;
  int global_envs_ = 0, env_offset_ = 0;

  // Per batch (T*E samples, in the buffer's column order).
  int batch_size_ = 0;
  Mat<float> old_values_, returns_, advantages_;  // 1 x T*E, as the loss sees them
  StepMat<float> truncation_values_;              // T x E
  Vec<float> bootstrap_values_;                   // E
  Mat<float> final_values_;                       // 1 x number of time-outs
  std::vector<int> order_;                        // minibatch shuffle, over the whole batch
  std::vector<int> mb_columns_;                   // this rank's buffer columns of the minibatch
  Mat<float> kl_ref_mean_, kl_ref_log_std_;       // act x T*E: each sample's policy at its last visit (KL)

  // Per minibatch.
  Mat<float> mb_obs_, mb_actions_, mb_old_mean_, mb_old_log_std_, mb_old_log_prob_, mb_adv_, mb_old_value_, mb_returns_;
  Vec<float> log_std_;
};

}  // namespace masa::ppo
