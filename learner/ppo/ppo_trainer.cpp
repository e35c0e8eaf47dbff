#include "learner/ppo/ppo_trainer.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

#include "common/core/check.hpp"

namespace masa::ppo {
namespace {

PpoLossConfig lossConfig(const config::PpoConfig& c) {
  PpoLossConfig l;
  l.e_clip = c.e_clip;
  l.entropy_coef = c.entropy_coef;
  l.critic_coef = c.critic_coef;
  l.bounds_loss_coef = c.bounds_loss_coef;
  l.soft_bound = c.soft_bound;
  l.clip_value = true;  // rl_games' clip_value, on in every task of the paper
  return l;
}

// Flat 1 x T*E view of a T x E row-major matrix: the order of the obs columns.
Eigen::Map<Mat<float>> flat(StepMat<float>& m) { return {m.data(), 1, m.size()}; }

double sum(const float* x, Eigen::Index n) {
  double s = 0;
  for (Eigen::Index i = 0; i < n; ++i) s += x[i];
  return s;
}

double squaredDeviations(const float* x, Eigen::Index n, double m) {
  double s = 0;
  for (Eigen::Index i = 0; i < n; ++i) s += (x[i] - m) * (x[i] - m);
  return s;
}

// The loss statistics a minibatch reports, packed to be summed across ranks in one call.
enum LossStat { kActor, kCritic, kEntropy, kBounds, kTotal, kSymPolicy, kSymValue, kKl, kClip, kNumLossStats };

}  // namespace

PpoTrainer::PpoTrainer(model::ActorCritic<float>& model, nn::Adam<float>& adam, const config::PpoConfig& config,
                       cluster::Communicator& ranks)
    : ranks_(&ranks),
      model_(&model),
      adam_(&adam),
      config_(config),
      gae_{config.gamma, config.tau, config.value_bootstrap},
      loss_(lossConfig(config), model.actDim(), config.minibatch_size),
      lr_(parseLrSchedule(config.lr_schedule), config.learning_rate, config.kl_threshold, config.lr_min,
          config.lr_max) {
  MASA_CHECK(config.mini_epochs > 0, "mini_epochs must be positive, got " << config.mini_epochs);
  const int m = config.minibatch_size, o = model.obsDim(), a = model.actDim();
  mb_obs_.resize(o, m);
  mb_actions_.resize(a, m);
  mb_old_mean_.resize(a, m);
  mb_old_log_std_.resize(a, m);
  mb_old_log_prob_.resize(1, m);
  mb_adv_.resize(1, m);
  mb_old_value_.resize(1, m);
  mb_returns_.resize(1, m);
  log_std_.resize(a);
  adam_->config().lr = static_cast<float>(lr_.lr());
}

PpoStats PpoTrainer::update(RolloutBuffer& buffer, Rng& rng) {
  prepare(buffer);
  return optimize(buffer, rng);
}

void PpoTrainer::resizeForBatch(const RolloutBuffer& buffer) {
  MASA_CHECK(buffer.obsDim() == model_->obsDim() && buffer.actDim() == model_->actDim(),
             "rollout buffer is obs " << buffer.obsDim() << " / act " << buffer.actDim() << ", model obs "
                                      << model_->obsDim() << " / act " << model_->actDim());
  const int n = buffer.size();
  MASA_CHECK(n > 0, "empty rollout buffer");
  // Every rank's environments, for the whole batch's layout (one collective per update).
  int global_envs = buffer.numEnvs(), env_offset = 0;
  if (ranks_->size() > 1) {
    const std::vector<int64_t> envs = ranks_->gather(buffer.numEnvs());
    const std::vector<int64_t> horizons = ranks_->gather(buffer.horizon());
    global_envs = env_offset = 0;
    for (int r = 0; r < ranks_->size(); ++r) {
      MASA_CHECK(horizons[r] == buffer.horizon(), "learner rank " << r << " has horizon " << horizons[r] << ", this rank "
                                                                   << buffer.horizon());
      if (r < ranks_->rank()) env_offset += static_cast<int>(envs[r]);
      global_envs += static_cast<int>(envs[r]);
    }
  }
  const int64_t global_size = static_cast<int64_t>(global_envs) * buffer.horizon();
  if (n == batch_size_ && truncation_values_.cols() == buffer.numEnvs() && global_size == global_size_ &&
      env_offset == env_offset_)
    return;
  global_size_ = global_size;
  global_envs_ = global_envs;
  env_offset_ = env_offset;
  batch_size_ = n;
  old_values_.resize(1, n);
  returns_.resize(1, n);
  advantages_.resize(1, n);
  truncation_values_.resize(buffer.horizon(), buffer.numEnvs());
  bootstrap_values_.resize(buffer.numEnvs());
  order_.resize(static_cast<std::size_t>(global_size));
  for (int i = 0; i < global_size; ++i) order_[i] = i;
  mb_columns_.resize(static_cast<std::size_t>(config_.minibatch_size));
}

void PpoTrainer::evaluateValues(const ConstMatRef<float>& obs, float* out) {
  const Eigen::Index n = obs.cols(), chunk = config_.minibatch_size;
  for (Eigen::Index start = 0; start < n; start += chunk) {
    const Eigen::Index len = std::min(chunk, n - start);
    const auto v = model_->criticValue(obs.middleCols(start, len));
    for (Eigen::Index i = 0; i < len; ++i) out[start + i] = v(0, i);
  }
}

void PpoTrainer::prepare(RolloutBuffer& buffer) {
  resizeForBatch(buffer);
  if (config_.value_bootstrap) buffer.checkFinalObs();
  model::ActorCritic<float>& model = *model_;

  if (model.config().normalize_obs) {
    Eigen::VectorXd moments = model.obsNormalizer().batchMoments(buffer.obs());
    sumAcrossRanks(moments.data(), static_cast<int>(moments.size()));
    model.obsNormalizer().mergeMoments(moments);
  }

  // Critic values of everything GAE needs, then real units.
  evaluateValues(buffer.obs(), buffer.values().data());
  evaluateValues(buffer.bootstrapObs(), bootstrap_values_.data());
  const int num_final = buffer.numFinalObs();
  final_values_.resize(1, num_final);
  if (num_final > 0) evaluateValues(buffer.finalObs(), final_values_.data());
  if (config_.normalize_value) {
    auto& vn = model.valueNormalizer();
    auto values = flat(buffer.values());
    vn.denormalize(values, values);
    Eigen::Map<Mat<float>> boot(bootstrap_values_.data(), 1, bootstrap_values_.size());
    vn.denormalize(boot, boot);
    if (num_final > 0) vn.denormalize(final_values_, final_values_);
  }
  truncation_values_.setZero();
  for (int k = 0; k < num_final; ++k) {
    const FinalObsEntry& f = buffer.finalObsEntry(k);
    truncation_values_(f.t, f.e) = final_values_(0, k);
  }

  computeGae<float>(gae_, buffer.rewards(), buffer.terminated(), buffer.truncated(), buffer.values(),
                    truncation_values_, bootstrap_values_, buffer.advantages(), buffer.returns());

  // Batch statistics over every rank's share: sums, then sums of squares about the whole batch's means.
  const Eigen::Index n = batch_size_;
  const float* v = buffer.values().data();
  const float* r = buffer.returns().data();
  const float* a = buffer.advantages().data();
  double sums[4] = {sum(v, n), sum(r, n), sum(a, n), static_cast<double>(n)};
  sumAcrossRanks(sums, 4);
  const double total = sums[3];
  prepared_ = PpoStats{};
  prepared_.mean_value = sums[0] / total;
  prepared_.mean_return = sums[1] / total;
  prepared_.mean_advantage = sums[2] / total;
  double squares[2] = {squaredDeviations(r, n, prepared_.mean_return), squaredDeviations(a, n, prepared_.mean_advantage)};
  sumAcrossRanks(squares, 2);
  const double var_r = squares[0] / total, var_a = squares[1] / total;  // population
  // R - V is the advantage.
  prepared_.explained_variance = var_r > 0 ? 1.0 - var_a / var_r : 0.0;

  // The critic trains on normalized targets; its old outputs are re-expressed with the new stats.
  if (config_.normalize_value) {
    auto& vn = model.valueNormalizer();
    Eigen::VectorXd moments = vn.batchMoments(flat(buffer.returns()));
    sumAcrossRanks(moments.data(), static_cast<int>(moments.size()));
    vn.mergeMoments(moments);
    vn.normalize(flat(buffer.values()), old_values_);
    vn.normalize(flat(buffer.returns()), returns_);
  } else {
    old_values_ = flat(buffer.values());
    returns_ = flat(buffer.returns());
  }

  advantages_ = flat(buffer.advantages());
  if (config_.normalize_advantage) {
    const double m = prepared_.mean_advantage;
    const double sd = total > 1 ? std::sqrt(var_a * total / (total - 1)) : 0.0;
    const float shift = static_cast<float>(m), scale = static_cast<float>(1.0 / (sd + 1e-8));
    advantages_.array() = (advantages_.array() - shift) * scale;
  }
}

PpoStats PpoTrainer::optimize(const RolloutBuffer& buffer, Rng& rng) {
  MASA_CHECK(buffer.size() == batch_size_, "optimize() on a buffer of " << buffer.size() << " samples, prepared "
                                                                        << batch_size_);
  model::ActorCritic<float>& model = *model_;
  auto& params = model.params();
  // A full batch is a whole number of minibatches of minibatch_size (the learner checks it). A batch
  // short of lost environments splits into as many minibatches as it needs, of equal sizes at most
  // minibatch_size, so that every sample is used once per mini-epoch and no step is a tiny one.
  const int minibatches_per_mini_epoch =
      static_cast<int>((global_size_ + config_.minibatch_size - 1) / config_.minibatch_size);
  const bool parallel = ranks_->size() > 1;
  const float max_norm = static_cast<float>(config_.grad_norm);
  const auto obs = buffer.obs();
  const auto actions = buffer.actions();
  const auto log_probs = buffer.logProbs();
  const int local_envs = buffer.numEnvs();
  PpoStats st = prepared_;
  // The KL that drives the learning rate compares each minibatch with the policy of its previous
  // visit (rl_games' update_mu_sigma): it starts at the collection policy and is overwritten after
  // every minibatch. The ratio of the surrogate keeps the collection log-probabilities.
  kl_ref_mean_ = buffer.means();
  const auto env_log_std = buffer.envLogStds();  // the same for all steps of an environment
  kl_ref_log_std_.resize(buffer.actDim(), buffer.size());
  for (int c = 0; c < buffer.size(); ++c) kl_ref_log_std_.col(c) = env_log_std.col(c % buffer.numEnvs());

  for (int mini_epoch = 0; mini_epoch < config_.mini_epochs; ++mini_epoch) {
    // Fisher-Yates with the raw engine output: the same permutation on every standard library (and
    // on every rank: they share the generator's state).
    for (int64_t i = global_size_ - 1; i > 0; --i)
      std::swap(order_[i], order_[static_cast<int64_t>(rng() % static_cast<uint64_t>(i + 1))]);

    for (int k = 0; k < minibatches_per_mini_epoch; ++k) {
      const int64_t begin = static_cast<int64_t>(k) * global_size_ / minibatches_per_mini_epoch;
      const int64_t m_global = static_cast<int64_t>(k + 1) * global_size_ / minibatches_per_mini_epoch - begin;
      // This rank's samples of the minibatch: whole-batch column g = t * E + e is environment e's
      // step t; this rank holds environments [env_offset_, env_offset_ + local_envs).
      int m = 0;
      for (int64_t j = 0; j < m_global; ++j) {
        const int g = order_[begin + j];
        const int e = g % global_envs_ - env_offset_;
        if (e < 0 || e >= local_envs) continue;
        mb_columns_[m++] = (g / global_envs_) * local_envs + e;
      }
      const int* idx = mb_columns_.data();
      for (int j = 0; j < m; ++j) {
        const int c = idx[j];
        mb_obs_.col(j) = obs.col(c);
        mb_actions_.col(j) = actions.col(c);
        mb_old_mean_.col(j) = kl_ref_mean_.col(c);
        mb_old_log_std_.col(j) = kl_ref_log_std_.col(c);
        mb_old_log_prob_(0, j) = log_probs(0, c);
        mb_adv_(0, j) = advantages_(0, c);
        mb_old_value_(0, j) = old_values_(0, c);
        mb_returns_(0, j) = returns_(0, c);
      }

      double stats[kNumLossStats] = {};
      params.zeroGrad();
      if (m > 0) {
        model.forward(mb_obs_.leftCols(m));
        model.logStd(log_std_);
        const PpoLossBatch<float> batch{model.mean(),
                                        log_std_,
                                        model.value(),
                                        mb_actions_.leftCols(m),
                                        mb_old_log_prob_.leftCols(m),
                                        mb_old_mean_.leftCols(m),
                                        mb_old_log_std_.leftCols(m),
                                        mb_adv_.leftCols(m),
                                        mb_old_value_.leftCols(m),
                                        mb_returns_.leftCols(m)};
        const PpoLossStats ls = loss_.compute(batch);
        for (int j = 0; j < m; ++j) {
          kl_ref_mean_.col(idx[j]) = model.mean().col(j);
          kl_ref_log_std_.col(idx[j]) = log_std_;
        }
        model.backward(loss_.dmean(), loss_.dlogStd(), loss_.dvalue());
        stats[kActor] = ls.actor_loss;
        stats[kCritic] = ls.critic_loss;
        stats[kEntropy] = ls.entropy;
        stats[kBounds] = ls.bounds_loss;
        stats[kTotal] = ls.total_loss;
        stats[kSymPolicy] = model.symmetryPolicyLoss();
        stats[kSymValue] = model.symmetryValueLoss();
        stats[kKl] = ls.kl;
        stats[kClip] = ls.clip_fraction;
      }
      if (parallel) {
        // Each rank's terms are means over its m samples: weighted by m / m_global and summed,
        // they are the means over the whole minibatch.
        const double w = static_cast<double>(m) / static_cast<double>(m_global);
        auto& grads = params.grads();
        grads *= static_cast<float>(w);
        ranks_->sum(grads.data(), static_cast<int>(grads.size()));
        for (double& x : stats) x *= w;
        ranks_->sum(stats, kNumLossStats);
      }
      const double gn = max_norm > 0 ? nn::clipGradNorm(params, max_norm) : params.grads().norm();
      adam_->config().lr = static_cast<float>(lr_.lr());
      adam_->step();
      lr_.update(stats[kKl]);

      st.actor_loss += stats[kActor];
      st.critic_loss += stats[kCritic];
      st.entropy += stats[kEntropy];
      st.bounds_loss += stats[kBounds];
      st.total_loss += stats[kTotal];
      st.sym_policy_loss += stats[kSymPolicy];
      st.sym_value_loss += stats[kSymValue];
      st.kl += stats[kKl];
      st.clip_fraction += stats[kClip];
      st.grad_norm += gn;
      ++st.minibatches;
    }
  }
  const double inv = 1.0 / st.minibatches;
  for (double* x : {&st.actor_loss, &st.critic_loss, &st.entropy, &st.bounds_loss, &st.total_loss,
                    &st.sym_policy_loss, &st.sym_value_loss, &st.kl, &st.clip_fraction, &st.grad_norm})
    *x *= inv;
  st.lr = lr_.lr();
  return st;
}

}  // namespace masa::ppo
