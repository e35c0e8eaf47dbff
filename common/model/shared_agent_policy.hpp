// Policy mean a = sum_i Out_i Phi(x_i) over a stack of agents sharing Phi (see agent_maps.hpp).
#pragma once

#include <memory>

#include "common/model/agent_maps.hpp"
#include "common/model/agent_stack.hpp"
#include "common/nn/mlp.hpp"

namespace masa::model {

template <typename S>
class SharedAgentPolicy {
 public:
  SharedAgentPolicy(nn::ParameterSet<S>& params, const std::string& name, const AgentMaps* maps,
                    const std::vector<int>& hidden, nn::Activation activation);

  void initialize(Rng& rng, S last_layer_scale);

  // Mean action (act_dim x B) of normalized observations; caches for backward.
  Eigen::Block<Mat<S>> forward(const ConstMatRef<S>& obs);
  // The same mean without caches for backward (actors, robot runner): Phi's inference path, no
  // copy of the stacked input. Bit-identical to forward().
  Eigen::Block<Mat<S>> infer(const ConstMatRef<S>& obs);
  // Per-agent outputs y_i of the last forward (agent_output_dim x N*B).
  Eigen::Map<const Mat<S>> agentOutputs() const;

  // Accumulates parameter gradients of dL/dmean (+ optional extra dL/dy on the agent outputs).
  // If dobs is given it receives dL/dobs.
  void backward(const ConstMatRef<S>& dmean, const Mat<S>* extra_dagent = nullptr, MatRef<S>* dobs = nullptr);

  const AgentMaps& maps() const { return *maps_; }
  nn::Mlp<S>& net() { return phi_; }
  const nn::Mlp<S>& net() const { return phi_; }

 private:
  const AgentMaps* maps_;
  std::vector<sym::SparseMap> output_t_;
  AgentStack<S> stack_;
  nn::Mlp<S> phi_;
  Mat<S> mean_, dagent_, dstack_;
  const S* agent_out_ = nullptr;  // Phi's output of the last forward (contiguous leftCols block)
  int batch_ = 0;

  Eigen::Block<Mat<S>> combine(const S* agent_out, int b);  // mean = sum_i Out_i y_i
};

}  // namespace masa::model
