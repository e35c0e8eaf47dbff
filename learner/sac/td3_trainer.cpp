#include "learner/sac/td3_trainer.hpp"

#include <istream>
#include <limits>
#include <ostream>
#include <stdexcept>

#include "common/core/binary_io.hpp"
#include "common/nn/serialize.hpp"
#include "learner/sac/sac_losses.hpp"
#include "common/model/squashed_gaussian.hpp"
#include "common/model/td3_noise.hpp"

namespace masa::sac {
template <typename S>
Td3Trainer<S>::Td3Trainer(const sym::SymmetrySpec& spec, SacPolicy<S>& policy, offline::TwinQ<S>& q,
                          offline::TwinQ<S>& q_target, const SacConfig& config)
    : policy_(&policy),
      policy_target_(spec, policy.shape()),
      q_(&q),
      q_target_(&q_target),
      config_(config),
      policy_net_(policy.params(), config.policy_lr, &policy_target_.params()),
      q_net_(q.params(), config.q_lr, &q_target.params()) {
  MASA_CHECK(config.td3_policy_delay >= 1, "TD3's policy delay must be at least 1");
  policy_net_.copyToTarget();
  stats_.entropy = std::numeric_limits<double>::quiet_NaN();
}

template <typename S>
void Td3Trainer<S>::explore(const ConstMatRef<S>& raw_obs, Rng& rng, MatRef<S> actions) {
  policy_->normalize(raw_obs, obs_n_);
  policy_->forward(obs_n_);
  eps_.resize(policy_->actDim(), obs_n_.cols());
  squashed_gaussian::drawNoise<S>(rng, eps_);
  td3::noisyActions<S>(policy_->mean(), eps_, static_cast<S>(config_.td3_exploration_noise),
                       std::numeric_limits<S>::infinity(), actions);
}

template <typename S>
S Td3Trainer<S>::criticLoss(const ReplayBatch<S>& batch, Rng& rng) {
  const int b = batch.size(), a = policy_->actDim();
  // The target: the smoothed target policy at o' and the target Qs; a constant for Q.
  policy_->normalize(batch.next_obs, next_n_);
  policy_target_.forward(next_n_);
  eps_.resize(a, b);
  act_.resize(a, b);
  squashed_gaussian::drawNoise<S>(rng, eps_);
  td3::noisyActions<S>(policy_target_.mean(), eps_, static_cast<S>(config_.td3_policy_noise),
                       static_cast<S>(config_.td3_noise_clip), act_);
  min_q_.resize(1, b);
  q_target_->minQ(next_n_, act_, min_q_);
  target_ = batch.rewards + batch.discount.cwiseProduct(min_q_);

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
S Td3Trainer<S>::actorLoss(const ReplayBatch<S>& batch) {
  const int b = batch.size(), a = policy_->actDim();
  policy_->normalize(batch.obs, obs_n_);
  policy_->forward(obs_n_);
  act_ = policy_->mean().array().tanh().matrix();
  // The actor follows Q_1 alone (Fujimoto et al.): Q_2 is neither run nor differentiated.
  const auto q1 = q_->q1Forward(obs_n_, act_);
  const S loss = -q1.mean();
  // dL/dQ_1 = -1/B; dL/da through Q_1. Q's own parameter gradients are not wanted: not computed,
  // and cleared (they were the critic step's) as the losses' contract says.
  dq1_.setConstant(1, b, S(-1) / S(b));
  da_.resize(a, b);
  q_->q1ActionGradient(dq1_, da_);
  q_->params().zeroGrad();
  dmean_ = (da_.array() * (S(1) - act_.array().square())).matrix();
  dlog_std_.setZero(a, b);
  policy_->params().zeroGrad();
  policy_->backward(dmean_, dlog_std_);
  stats_.symmetry_loss = static_cast<double>(policy_->symmetryLoss());
  return loss + policy_->symmetryLoss();
}

template <typename S>
SacStats Td3Trainer<S>::step(const ReplayBatch<S>& batch, Rng& rng) {
  stats_.q_loss = static_cast<double>(criticLoss(batch, rng));
  q_net_.step();
  ++steps_;
  if (steps_ % config_.td3_policy_delay == 0) {
    stats_.actor_loss = static_cast<double>(actorLoss(batch));
    policy_net_.step();
    q_net_.updateTarget(static_cast<S>(config_.polyak));
    policy_net_.updateTarget(static_cast<S>(config_.polyak));
  }
  return stats_;
}

namespace {
constexpr char kMagic[8] = {'M', 'A', 'S', 'A', 'T', 'D', '3', 'T'};
}

template <typename S>
void Td3Trainer<S>::save(std::ostream& os) const {
  os.write(kMagic, sizeof kMagic);
  io::writePod(os, steps_);
  policy_->save(os);
  policy_target_.save(os);
  nn::saveParameters(q_->params(), os);
  nn::saveParameters(q_target_->params(), os);
  policy_net_.saveOptimizer(os);
  q_net_.saveOptimizer(os);
}

template <typename S>
void Td3Trainer<S>::load(std::istream& is) {
  char magic[8] = {};
  is.read(magic, sizeof magic);
  if (!is || std::string(magic, 8) != std::string(kMagic, 8)) throw std::runtime_error("not a masa TD3 trainer state (bad magic)");
  if (!io::readPod(is, steps_)) throw std::runtime_error("TD3 trainer state: truncated");
  policy_->load(is, "TD3 trainer state");
  policy_target_.load(is, "TD3 trainer state (target policy)");
  nn::loadParameters(q_->params(), is, "TD3 trainer state (Q)");
  nn::loadParameters(q_target_->params(), is, "TD3 trainer state (target Q)");
  policy_net_.loadOptimizer(is);
  q_net_.loadOptimizer(is);
}

template class Td3Trainer<float>;
template class Td3Trainer<double>;

}  // namespace masa::sac
