#include "learner/offline/twin_q.hpp"

#include "common/nn/optimized_net.hpp"
#include "learner/offline/state_action_maps.hpp"

namespace masa::offline {

template <typename S>
TwinQ<S>::TwinQ(const sym::SymmetrySpec& spec, model::Method method, const std::vector<int>& hidden,
                nn::Activation activation)
    : TwinQ(spec, buildStateActionMaps(method, spec), hidden, activation) {}

template <typename S>
TwinQ<S>::TwinQ(const sym::SymmetrySpec& spec, model::AgentMaps pair_maps, const std::vector<int>& hidden,
                nn::Activation activation)
    : maps_(std::move(pair_maps)),
      obs_dim_(spec.obsDim()),
      act_dim_(spec.actDim()),
      q1_(params_, "q1", &maps_, hidden, {}, activation),
      q2_(params_, "q2", &maps_, hidden, {}, activation) {
  MASA_CHECK(maps_.obs_dim == obs_dim_ + act_dim_, "pair maps read " << maps_.obs_dim << " entries, the spec's pairs have "
                                                                     << obs_dim_ + act_dim_);
  params_.finalize();
}

template <typename S>
void TwinQ<S>::initialize(Rng& rng) {
  q1_.initialize(rng);
  q2_.initialize(rng);
}

template <typename S>
MatRef<S> TwinQ<S>::pairOf(const ConstMatRef<S>& obs, const ConstMatRef<S>& actions) {
  MASA_CHECK(obs.rows() == obs_dim_ && actions.rows() == act_dim_ && obs.cols() == actions.cols(),
             "Q input is " << obs.rows() << "x" << obs.cols() << " and " << actions.rows() << "x" << actions.cols()
                           << ", expected " << obs_dim_ << " and " << act_dim_ << " rows, equal columns");
  const Eigen::Index b = obs.cols();
  if (pair_.cols() < b) {
    pair_.resize(obs_dim_ + act_dim_, b);
    q_.resize(2, b);
  }
  auto pair = pair_.leftCols(b);
  pair.topRows(obs_dim_) = obs;
  pair.bottomRows(act_dim_) = actions;
  return pair;
}

template <typename S>
Eigen::Block<Mat<S>> TwinQ<S>::forward(const ConstMatRef<S>& obs, const ConstMatRef<S>& actions) {
  const auto pair = pairOf(obs, actions);
  const Eigen::Index b = pair.cols();
  auto q = q_.leftCols(b);
  q.row(0) = q1_.forward(pair);
  q.row(1) = q2_.forward(pair);
  return q_.block(0, 0, 2, b);
}

template <typename S>
Eigen::Block<Mat<S>> TwinQ<S>::q1Forward(const ConstMatRef<S>& obs, const ConstMatRef<S>& actions) {
  const auto pair = pairOf(obs, actions);
  const Eigen::Index b = pair.cols();
  q_.row(0).leftCols(b) = q1_.forward(pair);
  return q_.block(0, 0, 1, b);
}

template <typename S>
void TwinQ<S>::backward(const ConstMatRef<S>& dq, MatRef<S>* dactions) {
  if (!dactions) {
    q1_.backward(dq.row(0));
    q2_.backward(dq.row(1));
    return;
  }
  const Eigen::Index b = dq.cols();
  MASA_CHECK(dactions->rows() == act_dim_ && dactions->cols() == b, "dactions must be " << act_dim_ << " x " << b);
  dpair1_.resize(obs_dim_ + act_dim_, b);
  dpair2_.resize(obs_dim_ + act_dim_, b);
  MatRef<S> d1 = dpair1_, d2 = dpair2_;
  q1_.backward(dq.row(0), &d1);
  q2_.backward(dq.row(1), &d2);
  *dactions = d1.bottomRows(act_dim_) + d2.bottomRows(act_dim_);
}

template <typename S>
void TwinQ<S>::actionGradient(const ConstMatRef<S>& dq, MatRef<S> dactions) {
  const Eigen::Index b = dq.cols();
  MASA_CHECK(dq.rows() == 2 && dactions.rows() == act_dim_ && dactions.cols() == b,
             "dq must be 2 x B and dactions " << act_dim_ << " x B");
  dpair1_.resize(obs_dim_ + act_dim_, b);
  dpair2_.resize(obs_dim_ + act_dim_, b);
  q1_.inputGradient(dq.row(0), dpair1_);
  q2_.inputGradient(dq.row(1), dpair2_);
  dactions = dpair1_.bottomRows(act_dim_) + dpair2_.bottomRows(act_dim_);
}

template <typename S>
void TwinQ<S>::q1ActionGradient(const ConstMatRef<S>& dq1, MatRef<S> dactions) {
  const Eigen::Index b = dq1.cols();
  MASA_CHECK(dq1.rows() == 1 && dactions.rows() == act_dim_ && dactions.cols() == b,
             "dq1 must be 1 x B and dactions " << act_dim_ << " x B");
  dpair1_.resize(obs_dim_ + act_dim_, b);
  q1_.inputGradient(dq1, dpair1_);
  dactions = dpair1_.bottomRows(act_dim_);
}

template <typename S>
void TwinQ<S>::minQ(const ConstMatRef<S>& obs, const ConstMatRef<S>& actions, MatRef<S> out) {
  const auto q = forward(obs, actions);
  out = q.row(0).cwiseMin(q.row(1));
}

template <typename S>
void TwinQ<S>::moveTowards(const TwinQ& online, S rate) {
  nn::polyakUpdate(online.params_, params_, rate);
}

template class TwinQ<float>;
template class TwinQ<double>;

}  // namespace masa::offline
