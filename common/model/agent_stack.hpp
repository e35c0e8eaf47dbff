// Builds the stacked per-agent input X = [In_0 o + c_0, ..., In_(N-1) o + c_(N-1)]
// (agent_input_dim x N*B, agent i in columns [i*B, (i+1)*B)) and maps input gradients back.
#pragma once

#include "common/core/types.hpp"
#include "common/model/agent_maps.hpp"

namespace masa::model {

template <typename S>
class AgentStack {
 public:
  explicit AgentStack(const AgentMaps* maps);

  // Fills and returns the stack for a batch of observations (obs_dim x B).
  Eigen::Block<Mat<S>> build(const ConstMatRef<S>& obs);
  // dobs = sum_i In_i^T dX_i  (only needed for input gradients, e.g. in tests).
  void backward(const ConstMatRef<S>& dstack, MatRef<S> dobs) const;

  int batch() const { return batch_; }

 private:
  const AgentMaps* maps_;
  std::vector<sym::SparseMap> input_t_;
  Mat<S> constant_;
  Mat<S> stack_;
  int batch_ = 0;
};

}  // namespace masa::model
