#include "learner/offline/iql_losses.hpp"

#include <cmath>

#include "common/core/check.hpp"

namespace masa::offline {

template <typename S>
S expectileLoss(const ConstMatRef<S>& value, const ConstMatRef<S>& target, S tau, MatRef<S> dvalue) {
  MASA_CHECK(value.rows() == 1 && target.rows() == 1 && dvalue.rows() == 1 && value.cols() == target.cols() &&
                 value.cols() == dvalue.cols(),
             "expectile loss takes 1 x B rows of equal length");
  const Eigen::Index b = value.cols();
  S loss = S(0);
  for (Eigen::Index k = 0; k < b; ++k) {
    const S u = target(0, k) - value(0, k);
    const S w = u < S(0) ? S(1) - tau : tau;
    loss += w * u * u;
    dvalue(0, k) = S(-2) * w * u / S(b);
  }
  return loss / S(b);
}

template <typename S>
void advantageWeights(const ConstMatRef<S>& advantage, S beta, S max_weight, MatRef<S> weights) {
  MASA_CHECK(advantage.cols() == weights.cols() && advantage.rows() == weights.rows(), "weights must match the advantages");
  // exp overflows to inf for large advantages; min() then clips it like any other large weight.
  weights = (beta * advantage.array()).exp().min(max_weight).matrix();
}

template <typename S>
S tdLoss(const ConstMatRef<S>& q, const ConstMatRef<S>& target, MatRef<S> dq) {
  MASA_CHECK(target.rows() == 1 && q.cols() == target.cols() && dq.rows() == q.rows() && dq.cols() == q.cols(),
             "TD loss takes K x B values and a 1 x B target");
  const Eigen::Index b = q.cols();
  dq = q.rowwise() - target.row(0);
  const S loss = dq.squaredNorm() / S(b);
  dq *= S(2) / S(b);
  return loss;
}

template float expectileLoss<float>(const ConstMatRef<float>&, const ConstMatRef<float>&, float, MatRef<float>);
template double expectileLoss<double>(const ConstMatRef<double>&, const ConstMatRef<double>&, double, MatRef<double>);
template void advantageWeights<float>(const ConstMatRef<float>&, float, float, MatRef<float>);
template void advantageWeights<double>(const ConstMatRef<double>&, double, double, MatRef<double>);
template float tdLoss<float>(const ConstMatRef<float>&, const ConstMatRef<float>&, MatRef<float>);
template double tdLoss<double>(const ConstMatRef<double>&, const ConstMatRef<double>&, MatRef<double>);

}  // namespace masa::offline
