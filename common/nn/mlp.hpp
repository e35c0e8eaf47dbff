// Multi-layer perceptron with batched forward and backward written once.
//
// Parameters live in a ParameterSet (flat); activation buffers are owned here and sized by
// capacity: a batch up to the largest seen so far reuses them (leftCols views), so the training
// loop allocates nothing after its first step.
#pragma once

#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/nn/activation.hpp"
#include "common/nn/gemm.hpp"
#include "common/nn/parameter_set.hpp"

namespace masa::nn {

struct MlpShape {
  int input = 0;
  std::vector<int> hidden;                 // widths of hidden layers, e.g. {400, 200, 100}
  int output = 0;
  Activation hidden_activation = Activation::kElu;
  Activation output_activation = Activation::kIdentity;
};

template <typename S>
class Mlp {
 public:
  // Reserves "<name>.layer<k>.weight" (out x in) and "<name>.layer<k>.bias" (out) in `params`.
  Mlp(ParameterSet<S>& params, const std::string& name, const MlpShape& shape);

  const MlpShape& shape() const { return shape_; }
  int numLayers() const { return static_cast<int>(layers_.size()); }
  int numParams() const;

  // PyTorch's default Linear init: weight and bias ~ U(-1/sqrt(fan_in), 1/sqrt(fan_in)).
  // Optional `last_layer_scale` multiplies the last layer's weights (small policy heads).
  void initialize(Rng& rng, S last_layer_scale = S(1));

  // Ensures buffers for `batch` columns (grows only).
  void reserve(int batch);

  // Forward on x (input x B). Caches what backward needs; returns the output (output x B), a view
  // valid until the next forward.
  Eigen::Block<Mat<S>> forward(const ConstMatRef<S>& x);
  // Forward without caching for backward (inference; may still use internal buffers).
  Eigen::Block<Mat<S>> infer(const ConstMatRef<S>& x);

  // Backward of the last forward: grads += dL/dparams; if dx is given, dx = dL/dx (input x B).
  void backward(const ConstMatRef<S>& dy, MatRef<S>* dx = nullptr);

 private:
  struct Layer {
    int in, out, w_offset, b_offset;
    Activation act;
  };
  ParameterSet<S>* params_;
  MlpShape shape_;
  std::vector<Layer> layers_;
  // Per layer: pre-activation z and post-activation y, capacity columns.
  std::vector<Mat<S>> z_, y_;
  Mat<S> input_;  // copy of the last forward's input (needed for the first layer's weight grad)
  Mat<S> grad_a_, grad_b_;  // backward's dz, alternating between layers (widest layer x capacity)
  // Products run on owned packing buffers (see gemm.hpp); per layer: forward, weight grad, input grad.
  GemmWorkspace<S> gemm_;
  std::vector<GemmPlan> plans_;
  int capacity_ = 0;
  int batch_ = -1;  // columns of the last forward(); -1 when there is no cache for backward
};

}  // namespace masa::nn
