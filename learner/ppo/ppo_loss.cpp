#include "learner/ppo/ppo_loss.hpp"

#include <algorithm>
#include <cmath>

#include "common/core/check.hpp"
#include "common/model/diag_gaussian.hpp"

namespace masa::ppo {

template <typename S>
PpoLoss<S>::PpoLoss(const PpoLossConfig& config, int act_dim, int max_batch)
    : config_(config), act_dim_(act_dim), max_batch_(max_batch) {
  MASA_CHECK(act_dim > 0 && max_batch > 0, "PpoLoss needs positive sizes, got act " << act_dim << ", batch "
                                                                                    << max_batch);
  MASA_CHECK(config.e_clip > 0, "e_clip must be positive, got " << config.e_clip);
  log_prob_.resize(1, max_batch);
  dlog_prob_.resize(1, max_batch);
  kl_.resize(1, max_batch);
  dmean_.resize(act_dim, max_batch);
  dvalue_.resize(1, max_batch);
  dlog_std_.resize(act_dim);
}

template <typename S>
PpoLossStats PpoLoss<S>::compute(const PpoLossBatch<S>& in) {
  const Eigen::Index B = in.mean.cols();
  MASA_CHECK(B > 0 && B <= max_batch_, "minibatch of " << B << " samples, loss sized for " << max_batch_);
  MASA_CHECK(in.mean.rows() == act_dim_ && in.actions.rows() == act_dim_ && in.actions.cols() == B &&
                 in.old_mean.rows() == act_dim_ && in.old_mean.cols() == B && in.log_std.size() == act_dim_ &&
                 in.old_log_std.rows() == act_dim_ && (in.old_log_std.cols() == 1 || in.old_log_std.cols() == B),
             "policy inputs must be " << act_dim_ << " x " << B);
  auto row = [&](const ConstMatRef<S>& m) { return m.rows() == 1 && m.cols() == B; };
  MASA_CHECK(row(in.value) && row(in.old_log_prob) && row(in.advantages) && row(in.old_value) && row(in.returns),
             "per-sample inputs must be 1 x " << B);
  batch_ = static_cast<int>(B);
  const S inv_b = S(1) / static_cast<S>(B);
  const S e = static_cast<S>(config_.e_clip);
  auto logp = log_prob_.leftCols(B);
  auto dlogp = dlog_prob_.leftCols(B);
  auto dmean = dmean_.leftCols(B);
  auto dvalue = dvalue_.leftCols(B);
  PpoLossStats st;

  // Actor: d/dlogp of max(-A r, -A clip(r)) is -A r where the unclipped term is the larger one
  // (inside the clip range the two are equal and share that gradient), else 0.
  model::gaussian::logProb<S>(in.mean, in.log_std, in.actions, logp);
  double actor = 0;
  long clipped = 0;
  for (Eigen::Index b = 0; b < B; ++b) {
    const S a = in.advantages(0, b);
    const S ratio = std::exp(logp(0, b) - in.old_log_prob(0, b));
    const S surr = -a * ratio;
    const S surr_clipped = -a * std::clamp(ratio, S(1) - e, S(1) + e);
    actor += static_cast<double>(std::max(surr, surr_clipped));
    dlogp(0, b) = surr >= surr_clipped ? surr * inv_b : S(0);
    clipped += std::abs(ratio - S(1)) > e ? 1 : 0;
  }
  st.actor_loss = actor / static_cast<double>(B);
  st.clip_fraction = static_cast<double>(clipped) / static_cast<double>(B);
  dlog_std_.setZero();
  model::gaussian::logProbBackward<S>(in.mean, in.log_std, in.actions, dlogp, dmean, dlog_std_);

  // Entropy is the same for every sample (shared log-std): d entropy / d log_std_d = 1.
  st.entropy = static_cast<double>(model::gaussian::entropy<S>(in.log_std));
  dlog_std_.array() -= static_cast<S>(config_.entropy_coef);

  // Bounds loss on the mean.
  const S sb = static_cast<S>(config_.soft_bound);
  const S bounds_grad_scale = S(2) * static_cast<S>(config_.bounds_loss_coef) * inv_b;
  double bounds = 0;
  for (Eigen::Index b = 0; b < B; ++b)
    for (Eigen::Index d = 0; d < act_dim_; ++d) {
      const S mu = in.mean(d, b);
      const S excess = std::max(mu - sb, S(0)) + std::min(mu + sb, S(0));  // at most one is nonzero
      bounds += static_cast<double>(excess * excess);
      dmean(d, b) += bounds_grad_scale * excess;
    }
  st.bounds_loss = bounds / static_cast<double>(B);

  // Critic.
  const S critic_grad_scale = S(0.5) * static_cast<S>(config_.critic_coef) * inv_b;
  double critic = 0;
  for (Eigen::Index b = 0; b < B; ++b) {
    const S v = in.value(0, b), r = in.returns(0, b), old_v = in.old_value(0, b);
    const S err = v - r;
    const S loss = err * err;
    S c = loss, dc = S(2) * err;
    if (config_.clip_value) {
      const S moved = v - old_v;
      const S err_clipped = old_v + std::clamp(moved, -e, e) - r;
      const S loss_clipped = err_clipped * err_clipped;
      if (loss_clipped > loss) {
        c = loss_clipped;
        // Outside the clip range the clipped term is flat in v. Inside it, it is the unclipped term
        // itself (ahead only by rounding), with the same gradient.
        dc = moved > -e && moved < e ? S(2) * err_clipped : S(0);
      }
    }
    critic += static_cast<double>(c);
    dvalue(0, b) = critic_grad_scale * dc;
  }
  st.critic_loss = critic / static_cast<double>(B);

  auto kl = kl_.leftCols(B);
  model::gaussian::kl<S>(in.old_mean, in.old_log_std, in.mean, in.log_std, kl);
  st.kl = static_cast<double>(kl.sum()) / static_cast<double>(B);

  st.total_loss = st.actor_loss + 0.5 * config_.critic_coef * st.critic_loss - config_.entropy_coef * st.entropy +
                  config_.bounds_loss_coef * st.bounds_loss;
  return st;
}

template class PpoLoss<float>;
template class PpoLoss<double>;

}  // namespace masa::ppo
