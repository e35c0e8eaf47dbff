#include "common/model/shared_agent_critic.hpp"

namespace masa::model {
namespace {
// Psi is every hidden layer but the last, whose width is the feature size fed to Theta.
nn::MlpShape psiShape(int input, const std::vector<int>& hidden, nn::Activation activation) {
  MASA_CHECK(!hidden.empty(), "a critic needs at least one hidden layer (the feature width)");
  return nn::MlpShape{input, std::vector<int>(hidden.begin(), hidden.end() - 1), hidden.back(), activation, activation};
}
}  // namespace

template <typename S>
SharedAgentCritic<S>::SharedAgentCritic(nn::ParameterSet<S>& params, const std::string& name, const AgentMaps* maps,
                                        const std::vector<int>& hidden, const std::vector<int>& head_hidden,
                                        nn::Activation activation)
    : maps_(maps),
      stack_(maps),
      psi_(params, name + ".psi", psiShape(maps->agent_input_dim, hidden, activation)),
      theta_(params, name + ".theta", nn::MlpShape{hidden.back(), head_hidden, 1, activation, nn::Activation::kIdentity}),
      pool_(maps->pool.cast<S>()) {}

template <typename S>
void SharedAgentCritic<S>::initialize(Rng& rng) {
  psi_.initialize(rng);
  theta_.initialize(rng);
}

template <typename S>
Eigen::Block<Mat<S>> SharedAgentCritic<S>::forward(const ConstMatRef<S>& obs) {
  const int b = static_cast<int>(obs.cols());
  const int n = maps_->num_agents, p = maps_->numPooled();
  batch_ = b;
  auto f = psi_.forward(stack_.build(obs));
  const Eigen::Index h = f.rows();
  if (pooled_.cols() < static_cast<Eigen::Index>(p) * b) pooled_.resize(h, static_cast<Eigen::Index>(p) * b);
  auto pooled = pooled_.leftCols(static_cast<Eigen::Index>(p) * b);
  for (int q = 0; q < p; ++q) {
    auto out = pooled.middleCols(static_cast<Eigen::Index>(q) * b, b);
    out.setZero();
    for (int i = 0; i < n; ++i)
      if (pool_(q, i) != S(0)) out.noalias() += pool_(q, i) * f.middleCols(static_cast<Eigen::Index>(i) * b, b);
  }
  return theta_.forward(pooled);
}

template <typename S>
void SharedAgentCritic<S>::backward(const ConstMatRef<S>& dvalues, MatRef<S>* dobs) {
  backwardThrough(dvalues, dobs, true);
}

template <typename S>
void SharedAgentCritic<S>::inputGradient(const ConstMatRef<S>& dvalues, MatRef<S> dobs) {
  backwardThrough(dvalues, &dobs, false);
}

template <typename S>
void SharedAgentCritic<S>::backwardThrough(const ConstMatRef<S>& dvalues, MatRef<S>* dobs, bool parameter_grads) {
  const int b = batch_;
  const int n = maps_->num_agents, p = maps_->numPooled();
  MASA_CHECK(dvalues.rows() == 1 && dvalues.cols() == static_cast<Eigen::Index>(p) * b,
             "value gradient is " << dvalues.rows() << "x" << dvalues.cols() << ", expected 1x" << p * b);
  const Eigen::Index h = pooled_.rows();
  if (dpooled_.cols() < static_cast<Eigen::Index>(p) * b) dpooled_.resize(h, static_cast<Eigen::Index>(p) * b);
  MatRef<S> dpooled = dpooled_.leftCols(static_cast<Eigen::Index>(p) * b);
  if (parameter_grads)
    theta_.backward(dvalues, &dpooled);
  else
    theta_.inputGradient(dvalues, dpooled);
  if (dfeatures_.cols() < static_cast<Eigen::Index>(n) * b) dfeatures_.resize(h, static_cast<Eigen::Index>(n) * b);
  auto df = dfeatures_.leftCols(static_cast<Eigen::Index>(n) * b);
  for (int i = 0; i < n; ++i) {
    auto dfi = df.middleCols(static_cast<Eigen::Index>(i) * b, b);
    dfi.setZero();
    for (int q = 0; q < p; ++q)
      if (pool_(q, i) != S(0)) dfi.noalias() += pool_(q, i) * dpooled.middleCols(static_cast<Eigen::Index>(q) * b, b);
  }
  if (dobs) {
    const Eigen::Index nb = static_cast<Eigen::Index>(n) * b;
    if (dstack_.cols() < nb) dstack_.resize(maps_->agent_input_dim, nb);
    MatRef<S> ds = dstack_.leftCols(nb);
    if (parameter_grads)
      psi_.backward(df, &ds);
    else
      psi_.inputGradient(df, ds);
    stack_.backward(ds, *dobs);
  } else {
    psi_.backward(df);
  }
}

template class SharedAgentCritic<float>;
template class SharedAgentCritic<double>;

}  // namespace masa::model
