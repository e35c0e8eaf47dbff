// Critic V = Theta(pool_p(Psi(x_0), ..., Psi(x_(N-1)))) over the agent stack of agent_maps.hpp.
// MASA and MA pool by the mean over agents (so V is invariant for MASA); SASA keeps one value per
// orbit copy; SA is the single-agent case, i.e. a plain MLP split into Psi and a head Theta.
#pragma once

#include "common/model/agent_maps.hpp"
#include "common/model/agent_stack.hpp"
#include "common/nn/mlp.hpp"

namespace masa::model {

template <typename S>
class SharedAgentCritic {
 public:
  // hidden: widths of Psi (its last width is the feature size); head_hidden: Theta's hidden widths.
  SharedAgentCritic(nn::ParameterSet<S>& params, const std::string& name, const AgentMaps* maps,
                    const std::vector<int>& hidden, const std::vector<int>& head_hidden, nn::Activation activation);

  void initialize(Rng& rng);

  // Values of every pooled copy: 1 x (numPooled * B); copy 0 (the first B columns) is V(o).
  Eigen::Block<Mat<S>> forward(const ConstMatRef<S>& obs);
  // Gradient of the last forward's values (1 x numPooled*B). dobs optional as in the policy.
  void backward(const ConstMatRef<S>& dvalues, MatRef<S>* dobs = nullptr);
  // dobs = dL/dobs of the last forward only, the parameters' gradients left as they are (an actor
  // trained through this critic).
  void inputGradient(const ConstMatRef<S>& dvalues, MatRef<S> dobs);

  // Psi, the per-agent feature network (the critic's bulk; Theta is a small head).
  const nn::Mlp<S>& featureNet() const { return psi_; }

 private:
  void backwardThrough(const ConstMatRef<S>& dvalues, MatRef<S>* dobs, bool parameter_grads);

  const AgentMaps* maps_;
  AgentStack<S> stack_;
  nn::Mlp<S> psi_;
  nn::Mlp<S> theta_;
  Mat<S> pool_;
  Mat<S> pooled_, dpooled_, dfeatures_, dstack_;
  int batch_ = 0;
};

}  // namespace masa::model
