#include "learner/sac/sac_losses.hpp"

#include <cmath>

#include "common/core/check.hpp"

namespace masa::sac {

template <typename S>
void softQTarget(const ConstMatRef<S>& rewards, const ConstMatRef<S>& discount, const ConstMatRef<S>& min_q_next,
                 const ConstMatRef<S>& log_prob_next, S alpha, MatRef<S> target) {
  MASA_CHECK(rewards.cols() == discount.cols() && rewards.cols() == min_q_next.cols() &&
                 rewards.cols() == log_prob_next.cols() && rewards.cols() == target.cols(),
             "soft Q target takes 1 x B rows of equal length");
  target = rewards + discount.cwiseProduct(min_q_next - alpha * log_prob_next);
}

template <typename S>
S twinQLoss(const ConstMatRef<S>& q, const ConstMatRef<S>& target, MatRef<S> dq) {
  MASA_CHECK(q.rows() == 2 && target.rows() == 1 && q.cols() == target.cols() && dq.rows() == 2 && dq.cols() == q.cols(),
             "twin Q loss takes 2 x B values and a 1 x B target");
  const Eigen::Index b = q.cols();
  dq = q.rowwise() - target.row(0);
  const S loss = dq.squaredNorm() / S(b);
  dq *= S(2) / S(b);
  return loss;
}

template <typename S>
S actorLoss(const ConstMatRef<S>& log_prob, const ConstMatRef<S>& q, S alpha, MatRef<S> dlog_prob, MatRef<S> dq) {
  MASA_CHECK(q.rows() == 2 && log_prob.cols() == q.cols() && dq.rows() == 2 && dq.cols() == q.cols() &&
                 dlog_prob.cols() == q.cols(),
             "actor loss takes a 1 x B log-prob and 2 x B values");
  const Eigen::Index b = q.cols();
  S loss = S(0);
  dq.setZero();
  for (Eigen::Index k = 0; k < b; ++k) {
    const int arg = q(1, k) < q(0, k) ? 1 : 0;
    loss += alpha * log_prob(0, k) - q(arg, k);
    dq(arg, k) = S(-1) / S(b);
    dlog_prob(0, k) = alpha / S(b);
  }
  return loss / S(b);
}

template <typename S>
S temperatureLoss(S log_alpha, const ConstMatRef<S>& log_prob, S target_entropy, S& dlog_alpha) {
  const S alpha = std::exp(log_alpha);
  const S mean = log_prob.mean() + target_entropy;
  dlog_alpha = -alpha * mean;
  return -alpha * mean;
}

#define MASA_SAC_LOSSES(S)                                                                                        \
  template void softQTarget<S>(const ConstMatRef<S>&, const ConstMatRef<S>&, const ConstMatRef<S>&,               \
                               const ConstMatRef<S>&, S, MatRef<S>);                                             \
  template S twinQLoss<S>(const ConstMatRef<S>&, const ConstMatRef<S>&, MatRef<S>);                               \
  template S actorLoss<S>(const ConstMatRef<S>&, const ConstMatRef<S>&, S, MatRef<S>, MatRef<S>);                 \
  template S temperatureLoss<S>(S, const ConstMatRef<S>&, S, S&);
MASA_SAC_LOSSES(float)
MASA_SAC_LOSSES(double)
#undef MASA_SAC_LOSSES

}  // namespace masa::sac
