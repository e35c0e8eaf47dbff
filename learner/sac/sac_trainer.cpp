#include "learner/sac/sac_trainer.hpp"

#include <cmath>
#include <istream>
#include <ostream>
#include <stdexcept>

#include "common/core/binary_io.hpp"
#include "common/nn/serialize.hpp"
#include "learner/sac/sac_losses.hpp"
#include "common/model/squashed_gaussian.hpp"

namespace masa::sac {
namespace {
// The temperature's one parameter, log alpha (so that alpha stays positive), ready for its Adam.
template <typename S>
nn::ParameterSet<S>& logAlphaSet(nn::ParameterSet<S>& set, double init_alpha) {
  set.reserve("log_alpha", 1);
  set.finalize();
  set.values()(0) = static_cast<S>(std::log(init_alpha));
  return set;
}
}  // namespace

template <typename S>
SacTrainer<S>::SacTrainer(SacPolicy<S>& policy, offline::TwinQ<S>& q, offline::TwinQ<S>& q_target,
                          const SacConfig& config)
    : policy_(&policy),
      q_(&q),
      q_target_(&q_target),
      config_(config),
      target_entropy_(config.target_entropy_per_dim * policy.actDim()),
      policy_net_(policy.params(), config.policy_lr),
      q_net_(q.params(), config.q_lr, &q_target.params()),
      alpha_net_(logAlphaSet(log_alpha_, config.init_alpha), config.alpha_lr) {}

template <typename S>
double SacTrainer<S>::alpha() const {
  return std::exp(static_cast<double>(logAlpha()));
}

template <typename S>
S SacTrainer<S>::criticLoss(const ReplayBatch<S>& batch, Rng& rng) {
  const int b = batch.size(), a = policy_->actDim();
  const S alpha = std::exp(logAlpha());
  // The target: a' ~ pi(o') and the target networks; a constant for Q.
  policy_->normalize(batch.next_obs, next_n_);
  policy_->forward(next_n_);
  eps_.resize(a, b);
  act_.resize(a, b);
  logp_.resize(1, b);
  squashed_gaussian::drawNoise<S>(rng, eps_);
  squashed_gaussian::sample<S>(policy_->mean(), policy_->logStd(), eps_, act_, logp_);
  min_q_.resize(1, b);
  q_target_->minQ(next_n_, act_, min_q_);
  target_.resize(1, b);
  softQTarget<S>(batch.rewards, batch.discount, min_q_, logp_, alpha, target_);

  policy_->normalize(batch.obs, obs_n_);
  const auto q = q_->forward(obs_n_, batch.actions);
  stats_.mean_q = static_cast<double>(q.row(0).mean());
  dq_.resize(2, b);
  const S loss = twinQLoss<S>(q, target_, dq_);
  q_->params().zeroGrad();
  q_->backward(dq_);
  return loss;
}

template <typename S>
S SacTrainer<S>::actorLoss(const ReplayBatch<S>& batch, Rng& rng) {
  const int b = batch.size(), a = policy_->actDim();
  const S alpha = std::exp(logAlpha());
  policy_->normalize(batch.obs, obs_n_);
  policy_->forward(obs_n_);
  eps_.resize(a, b);
  act_.resize(a, b);
  logp_.resize(1, b);
  squashed_gaussian::drawNoise<S>(rng, eps_);
  squashed_gaussian::sample<S>(policy_->mean(), policy_->logStd(), eps_, act_, logp_);
  const auto q = q_->forward(obs_n_, act_);
  dq_.resize(2, b);
  dlogp_.resize(1, b);
  const S loss = sac::actorLoss<S>(logp_, q, alpha, dlogp_, dq_);
  // dL/da through Q. Q's own parameter gradients are not wanted: not computed, and cleared (they
  // were the critic step's) as the losses' contract says.
  da_.resize(a, b);
  q_->actionGradient(dq_, da_);
  q_->params().zeroGrad();
  dmean_.resize(a, b);
  dlog_std_.resize(a, b);
  squashed_gaussian::sampleBackward<S>(policy_->logStd(), eps_, act_, da_, dlogp_, dmean_, dlog_std_);
  policy_->params().zeroGrad();
  policy_->backward(dmean_, dlog_std_);
  stats_.entropy = -static_cast<double>(logp_.mean());
  stats_.symmetry_loss = static_cast<double>(policy_->symmetryLoss());
  return loss + policy_->symmetryLoss();
}

template <typename S>
S SacTrainer<S>::temperatureLoss() {
  S dlog_alpha = S(0);
  const S loss = sac::temperatureLoss<S>(logAlpha(), logp_, static_cast<S>(target_entropy_), dlog_alpha);
  log_alpha_.zeroGrad();
  log_alpha_.grads()(0) = dlog_alpha;
  return loss;
}

template <typename S>
SacStats SacTrainer<S>::step(const ReplayBatch<S>& batch, Rng& rng) {
  stats_.q_loss = static_cast<double>(criticLoss(batch, rng));
  q_net_.step();
  stats_.actor_loss = static_cast<double>(actorLoss(batch, rng));
  policy_net_.step();
  stats_.alpha_loss = static_cast<double>(temperatureLoss());
  if (config_.autotune) alpha_net_.step();
  stats_.alpha = alpha();
  q_net_.updateTarget(static_cast<S>(config_.polyak));
  ++steps_;
  return stats_;
}

namespace {
constexpr char kMagic[8] = {'M', 'A', 'S', 'A', 'S', 'A', 'C', 'T'};
}

template <typename S>
void SacTrainer<S>::save(std::ostream& os) const {
  os.write(kMagic, sizeof kMagic);
  io::writePod(os, steps_);
  policy_->save(os);
  nn::saveParameters(q_->params(), os);
  nn::saveParameters(q_target_->params(), os);
  nn::saveParameters(log_alpha_, os);
  policy_net_.saveOptimizer(os);
  q_net_.saveOptimizer(os);
  alpha_net_.saveOptimizer(os);
}

template <typename S>
void SacTrainer<S>::load(std::istream& is) {
  char magic[8] = {};
  is.read(magic, sizeof magic);
  if (!is || std::string(magic, 8) != std::string(kMagic, 8)) throw std::runtime_error("not a masa SAC trainer state (bad magic)");
  if (!io::readPod(is, steps_)) throw std::runtime_error("SAC trainer state: truncated");
  policy_->load(is, "SAC trainer state");
  nn::loadParameters(q_->params(), is, "SAC trainer state (Q)");
  nn::loadParameters(q_target_->params(), is, "SAC trainer state (target Q)");
  nn::loadParameters(log_alpha_, is, "SAC trainer state (log alpha)");
  policy_net_.loadOptimizer(is);
  q_net_.loadOptimizer(is);
  alpha_net_.loadOptimizer(is);
}

template class SacTrainer<float>;
template class SacTrainer<double>;

}  // namespace masa::sac
