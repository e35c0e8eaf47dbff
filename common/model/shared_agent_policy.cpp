#include "common/model/shared_agent_policy.hpp"

namespace masa::model {

template <typename S>
SharedAgentPolicy<S>::SharedAgentPolicy(nn::ParameterSet<S>& params, const std::string& name, const AgentMaps* maps,
                                        const std::vector<int>& hidden, nn::Activation activation)
    : maps_(maps),
      stack_(maps),
      phi_(params, name, nn::MlpShape{maps->agent_input_dim, hidden, maps->agent_output_dim, activation,
                                      nn::Activation::kIdentity}) {
  for (const auto& m : maps->output) output_t_.push_back(m.transpose());
}

template <typename S>
void SharedAgentPolicy<S>::initialize(Rng& rng, S last_layer_scale) {
  phi_.initialize(rng, last_layer_scale);
}

template <typename S>
Eigen::Block<Mat<S>> SharedAgentPolicy<S>::forward(const ConstMatRef<S>& obs) {
  const int b = static_cast<int>(obs.cols());
  batch_ = b;
  agent_out_ = phi_.forward(stack_.build(obs)).data();
  return combine(agent_out_, b);
}

template <typename S>
Eigen::Block<Mat<S>> SharedAgentPolicy<S>::infer(const ConstMatRef<S>& obs) {
  const int b = static_cast<int>(obs.cols());
  agent_out_ = nullptr;  // Phi's caches for backward are gone
  return combine(phi_.infer(stack_.build(obs)).data(), b);
}

template <typename S>
Eigen::Block<Mat<S>> SharedAgentPolicy<S>::combine(const S* agent_out, int b) {
  const Eigen::Index nb = static_cast<Eigen::Index>(maps_->num_agents) * b;
  const Eigen::Map<const Mat<S>> y(agent_out, maps_->agent_output_dim, nb);
  if (mean_.cols() < b) mean_.resize(maps_->act_dim, b);
  auto mean = mean_.block(0, 0, mean_.rows(), b);
  mean.setZero();
  for (int i = 0; i < maps_->num_agents; ++i)
    maps_->output[i].template applyAdd<S>(y.middleCols(static_cast<Eigen::Index>(i) * b, b), mean);
  return mean;
}

template <typename S>
Eigen::Map<const Mat<S>> SharedAgentPolicy<S>::agentOutputs() const {
  MASA_CHECK(agent_out_ != nullptr, "agentOutputs() before forward()");
  return Eigen::Map<const Mat<S>>(agent_out_, maps_->agent_output_dim, static_cast<Eigen::Index>(maps_->num_agents) * batch_);
}

template <typename S>
void SharedAgentPolicy<S>::backward(const ConstMatRef<S>& dmean, const Mat<S>* extra_dagent, MatRef<S>* dobs) {
  const int b = batch_;
  const Eigen::Index nb = static_cast<Eigen::Index>(maps_->num_agents) * b;
  MASA_CHECK(dmean.cols() == b && dmean.rows() == maps_->act_dim, "dmean is " << dmean.rows() << "x" << dmean.cols());
  if (dagent_.cols() < nb) dagent_.resize(maps_->agent_output_dim, nb);
  auto dy = dagent_.leftCols(nb);
  for (int i = 0; i < maps_->num_agents; ++i)
    output_t_[i].template apply<S>(dmean, dy.middleCols(static_cast<Eigen::Index>(i) * b, b));
  if (extra_dagent) {
    MASA_CHECK(extra_dagent->rows() == dy.rows() && extra_dagent->cols() >= nb, "extra agent gradient has wrong shape");
    dy += extra_dagent->leftCols(nb);
  }
  if (dobs) {
    if (dstack_.cols() < nb) dstack_.resize(maps_->agent_input_dim, nb);
    MatRef<S> ds = dstack_.leftCols(nb);
    phi_.backward(dy, &ds);
    stack_.backward(ds, *dobs);
  } else {
    phi_.backward(dy);
  }
}

template class SharedAgentPolicy<float>;
template class SharedAgentPolicy<double>;

}  // namespace masa::model
