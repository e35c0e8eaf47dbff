#include "common/model/agent_stack.hpp"

namespace masa::model {

template <typename S>
AgentStack<S>::AgentStack(const AgentMaps* maps) : maps_(maps) {
  for (const auto& m : maps->input) input_t_.push_back(m.transpose());
  constant_ = maps->input_constant.cast<S>();
}

template <typename S>
Eigen::Block<Mat<S>> AgentStack<S>::build(const ConstMatRef<S>& obs) {
  MASA_CHECK(obs.rows() == maps_->obs_dim, "observation has " << obs.rows() << " rows, expected " << maps_->obs_dim);
  const int b = static_cast<int>(obs.cols());
  const int n = maps_->num_agents;
  if (stack_.cols() < static_cast<Eigen::Index>(n) * b) stack_.resize(maps_->agent_input_dim, static_cast<Eigen::Index>(n) * b);
  batch_ = b;
  for (int i = 0; i < n; ++i) {
    auto xi = stack_.middleCols(static_cast<Eigen::Index>(i) * b, b);
    maps_->input[i].template apply<S>(obs, xi);
    if (constant_.col(i).any()) xi.colwise() += constant_.col(i);
  }
  return stack_.block(0, 0, stack_.rows(), static_cast<Eigen::Index>(n) * b);
}

template <typename S>
void AgentStack<S>::backward(const ConstMatRef<S>& dstack, MatRef<S> dobs) const {
  const int b = static_cast<int>(dobs.cols());
  MASA_CHECK(dstack.cols() == static_cast<Eigen::Index>(maps_->num_agents) * b, "stack gradient has wrong batch");
  dobs.setZero();
  for (int i = 0; i < maps_->num_agents; ++i)
    input_t_[i].template applyAdd<S>(dstack.middleCols(static_cast<Eigen::Index>(i) * b, b), dobs);
}

template class AgentStack<float>;
template class AgentStack<double>;

}  // namespace masa::model
