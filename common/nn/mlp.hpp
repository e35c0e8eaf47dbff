// Multi-layer perceptron with batched forward and backward written once.
//
// Parameters live in a ParameterSet (flat); activation buffers are owned here and sized by
// capacity: a batch up to the largest seen so far reuses them (leftCols views), so the training
// loop allocates nothing after its first step.
//
// Two engines behind one interface. In float on AVX-512 or AVX2 machines (dense::kAvailable) the layers
// run on the fused kernels of dense_kernels.hpp, and the batch is cut into chunks that the OpenMP
// threads take in turn: a chunk goes through every layer while its activations stay in L2, and
// each thread adds its weight gradients to its own partial, summed once at the end (no
// synchronization between layers). The chunk width is measured on the machine during the first
// training steps (chunk_tuner.hpp); no result depends on it. Otherwise (double, or neither) every product is one
// GemmWorkspace call and the elementwise work separate passes. Only post-activations are stored
// (f' is computed from them); hidden ones have their rows padded to a multiple of 16 so that
// every column starts 64-byte aligned.
#pragma once

#include <array>
#include <string>
#include <type_traits>
#include <vector>

#include "common/core/types.hpp"
#include "common/nn/activation.hpp"
#include "common/nn/chunk_tuner.hpp"
#include "common/nn/dense_kernels.hpp"
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
  // Forward without caching for backward (inference; may still use internal buffers). On frozen
  // parameters (ParameterSet::freeze) 1-4 columns read every W from a copy packed for that column
  // count on first use (dense::packForward): bit-identical, and faster (the robot runner's step).
  Eigen::Block<Mat<S>> infer(const ConstMatRef<S>& x);

  // Backward of the last forward: grads += dL/dparams; if dx is given, dx = dL/dx (input x B).
  void backward(const ConstMatRef<S>& dy, MatRef<S>* dx = nullptr);
  // dx = dL/dx of the last forward only; the parameters' gradients are left as they are. What a
  // network differentiated for another one's sake needs (SAC's and TD3's actor through Q): the
  // weight-gradient products are a third of a backward's work.
  void inputGradient(const ConstMatRef<S>& dy, MatRef<S> dx);

  // The fused engine's chunk width: measured during the first training steps, or forced (a
  // multiple of ChunkTuner::kBlock). Every width gives bit-identical results.
  const ChunkTuner& chunkTuner() const { return chunk_tuner_; }
  void forceChunkWidth(int columns) { chunk_tuner_.force(columns); }

 private:
  struct Layer {
    int in, out, w_offset, b_offset;
    Activation act;
  };
  static constexpr bool kFused = std::is_same_v<S, float> && dense::kAvailable;

  void forwardGeneric(const S* x, Eigen::Index ldx, int B);
  // The backward passes add parameter gradients only when weight_grads (else dx is required).
  void backwardGeneric(const ConstMatRef<S>& dy, MatRef<S>* dx, bool weight_grads);
  void forwardFused(const S* x, Eigen::Index ldx, int B, bool keep_input);
  void backwardFused(const ConstMatRef<S>& dy, MatRef<S>* dx, bool weight_grads);
  void checkBackward(const ConstMatRef<S>& dy, const MatRef<S>* dx) const;
  void inferPacked(const S* x, Eigen::Index ldx, int n);
  // Threads for a batch of B columns (1 inside a parallel region or for small batches).
  int threadsFor(int B, int min_columns_per_thread) const;
  // Columns per thread of a backward over B columns (what the chunk tuner sizes against).
  int backwardColumnsPerThread(int B) const;

  ParameterSet<S>* params_;
  MlpShape shape_;
  std::vector<Layer> layers_;
  std::vector<Mat<S>> y_;  // per layer: post-activation, capacity columns (hidden rows padded)
  Mat<S> input_;  // copy of the last forward's input (needed for the first layer's weight grad)
  int batch_ = -1;  // columns of the last forward(); -1 when there is no cache for backward
  int capacity_ = 0;

  // Generic engine: backward's dz alternating between two buffers (widest layer x capacity);
  // products on owned packing buffers (see gemm.hpp), per layer: forward, weight grad, input grad.
  Mat<S> grad_a_, grad_b_;
  GemmWorkspace<S> gemm_;
  std::vector<GemmPlan> plans_;

  // Fused engine: W^T of every layer packed for the input gradients; per thread two dz scratch
  // blocks (widest layer x chunk); per thread but the first a gradient partial of this MLP's
  // parameter range [param_begin_, param_begin_ + numParams()) (the first adds to the grads).
  Vec<S> packed_t_;
  std::vector<Eigen::Index> packed_t_offset_;
  std::vector<Mat<S>> scratch_;
  std::vector<Vec<S>> grad_partial_;
  int param_begin_ = 0;
  ChunkTuner chunk_tuner_;
  // Per column count n = 1..4: every layer's W packed for inference over n columns, one after the
  // other; built on the first such infer() of frozen parameters, so never stale.
  std::array<Vec<S>, dense::kMaxPackedColumns> inference_pack_;
  double forward_seconds_ = 0;  // of the last training forward, for the tuner
};

}  // namespace masa::nn
