// Batched MLP forward/backward on buffers that only grow, so steady-state training allocates nothing.
#include "common/nn/mlp.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "common/core/check.hpp"

namespace masa::nn {

namespace {
using Eigen::Index;

// The fused engine's unit of work: a thread takes whole blocks of columns through all layers
// (ChunkTuner chooses how many at a time), and the threads split a backward by blocks.
constexpr int kBlock = ChunkTuner::kBlock;
constexpr int kWidestChunk = ChunkTuner::kCandidates.back();
// Below these many columns per thread a second thread costs more than it saves (waking it takes
// microseconds; backward also zeroes and sums a gradient partial of the whole network).
constexpr int kMinForwardColumnsPerThread = 64;
constexpr int kMinBackwardColumnsPerThread = 256;

int paddedRows(int rows) { return (rows + 15) / 16 * 16; }

// [begin, end) of part t of nt of n items, in multiples of 16.
std::pair<int, int> columnRange(int n, int t, int nt) {
  const int per = ((n + nt - 1) / nt + 15) / 16 * 16;
  const int begin = std::min(n, t * per);
  return {begin, std::min(n, begin + per)};
}
}  // namespace

template <typename S>
Mlp<S>::Mlp(ParameterSet<S>& params, const std::string& name, const MlpShape& shape) : params_(&params), shape_(shape) {
  MASA_CHECK(shape.input > 0 && shape.output > 0,
             "MLP '" << name << "' needs positive input and output widths, got " << shape.input << " and " << shape.output);
  std::vector<int> widths{shape.input};
  for (int h : shape.hidden) {
    MASA_CHECK(h > 0, "MLP '" << name << "' has a hidden layer of width " << h);
    widths.push_back(h);
  }
  widths.push_back(shape.output);
  for (size_t k = 0; k + 1 < widths.size(); ++k) {
    Layer l;
    l.in = widths[k];
    l.out = widths[k + 1];
    const std::string prefix = name + ".layer" + std::to_string(k);
    l.w_offset = params.reserve(prefix + ".weight", l.out, l.in);
    l.b_offset = params.reserve(prefix + ".bias", l.out, 1);
    l.act = k + 2 == widths.size() ? shape.output_activation : shape.hidden_activation;
    layers_.push_back(l);
  }
  y_.resize(layers_.size());
  param_begin_ = layers_.front().w_offset;
  MASA_CHECK(layers_.back().b_offset + layers_.back().out == param_begin_ + numParams(),
             "MLP '" << name << "': its parameters are not one contiguous range");
  if constexpr (kFused) {
    Index size = 0;
    for (const Layer& l : layers_) {
      packed_t_offset_.push_back(size);
      size += dense::packedSize(l.in, l.out);
    }
    packed_t_.setZero(size);
  }
  // Buffers and plans for zero columns, so that even an empty first batch finds them consistent.
  capacity_ = -1;
  reserve(0);
}

template <typename S>
int Mlp<S>::numParams() const {
  int n = 0;
  for (const Layer& l : layers_) n += l.out * l.in + l.out;
  return n;
}

template <typename S>
void Mlp<S>::initialize(Rng& rng, S last_layer_scale) {
  params_->finalize();
  for (size_t k = 0; k < layers_.size(); ++k) {
    const Layer& l = layers_[k];
    const double bound = 1.0 / std::sqrt(static_cast<double>(l.in));
    std::uniform_real_distribution<double> dist(-bound, bound);
    const S scale = k + 1 == layers_.size() ? last_layer_scale : S(1);
    auto w = params_->value(l.w_offset, l.out, l.in);
    // Drawn column by column so the same seed gives the same weights whatever the storage order.
    for (int c = 0; c < l.in; ++c)
      for (int r = 0; r < l.out; ++r) w(r, c) = static_cast<S>(dist(rng)) * scale;
    auto b = params_->value(l.b_offset, l.out, 1);
    for (int r = 0; r < l.out; ++r) b(r) = static_cast<S>(dist(rng));
  }
}

template <typename S>
void Mlp<S>::reserve(int batch) {
  MASA_CHECK(batch >= 0, "MLP reserve: negative batch " << batch);
  if (batch <= capacity_) return;
  const int L = numLayers();
  int max_width = shape_.input, max_padded = 16;
  for (int k = 0; k < L; ++k) {
    // Zeroed, so that the padding rows hold numbers and the pages are touched here, not in a step.
    y_[k].setZero(k + 1 == L ? layers_[k].out : paddedRows(layers_[k].out), batch);
    max_width = std::max(max_width, layers_[k].out);
    max_padded = std::max(max_padded, paddedRows(layers_[k].out));
  }
  input_.setZero(shape_.input, batch);
  if constexpr (kFused) {
    const int threads = std::max(1, omp_get_max_threads());
    scratch_.resize(threads);
    for (Mat<S>& s : scratch_) s.setZero(max_padded, 2 * std::min(batch, kWidestChunk));
    grad_partial_.resize(threads - 1);
    for (Vec<S>& g : grad_partial_) g.setZero(numParams());
  } else {
    grad_a_.resize(max_width, batch);
    grad_b_.resize(max_width, batch);
    plans_.clear();
    for (const Layer& l : layers_) {
      plans_.push_back(GemmWorkspace<S>::plan(l.out, batch, l.in));
      plans_.push_back(GemmWorkspace<S>::plan(l.out, l.in, batch));
      plans_.push_back(GemmWorkspace<S>::plan(l.in, batch, l.out));
    }
    gemm_.reserve(plans_);
  }
  capacity_ = batch;
  batch_ = -1;  // the caches of an earlier forward are gone
}

template <typename S>
int Mlp<S>::threadsFor(int B, int min_columns_per_thread) const {
  if (omp_in_parallel()) return 1;
  return std::clamp(B / min_columns_per_thread, 1, std::max(1, omp_get_max_threads()));
}

template <typename S>
int Mlp<S>::backwardColumnsPerThread(int B) const {
  const int threads = std::min(threadsFor(B, kMinBackwardColumnsPerThread), static_cast<int>(scratch_.size()));
  return (B + std::max(threads, 1) - 1) / std::max(threads, 1);
}

template <typename S>
Eigen::Block<Mat<S>> Mlp<S>::forward(const ConstMatRef<S>& x) {
  MASA_CHECK(params_->finalized(), "MLP forward before the parameter set is finalized");
  MASA_CHECK(x.rows() == shape_.input, "MLP forward: input has " << x.rows() << " rows, expected " << shape_.input);
  const int B = static_cast<int>(x.cols());
  reserve(B);
  if constexpr (kFused) {
    const auto start = std::chrono::steady_clock::now();
    forwardFused(x.data(), x.outerStride(), B, true);
    forward_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  } else {
    input_.leftCols(B) = x;
    forwardGeneric(input_.data(), input_.rows(), B);
  }
  batch_ = B;
  return y_.back().block(0, 0, shape_.output, B);
}

template <typename S>
Eigen::Block<Mat<S>> Mlp<S>::infer(const ConstMatRef<S>& x) {
  MASA_CHECK(params_->finalized(), "MLP infer before the parameter set is finalized");
  MASA_CHECK(x.rows() == shape_.input, "MLP infer: input has " << x.rows() << " rows, expected " << shape_.input);
  const int B = static_cast<int>(x.cols());
  reserve(B);
  // Reads x directly and overwrites the activations: backward is no longer valid.
  batch_ = -1;
  if constexpr (kFused) {
    if (params_->frozen() && B >= 1 && B <= dense::kMaxPackedColumns)
      inferPacked(x.data(), x.outerStride(), B);
    else
      forwardFused(x.data(), x.outerStride(), B, false);
  } else {
    forwardGeneric(x.data(), x.outerStride(), B);
  }
  return y_.back().block(0, 0, shape_.output, B);
}

template <typename S>
void Mlp<S>::checkBackward(const ConstMatRef<S>& dy, const MatRef<S>* dx) const {
  const int B = batch_;
  MASA_CHECK(B >= 0, "MLP backward needs a forward() first (infer() does not keep caches)");
  MASA_CHECK(dy.rows() == shape_.output && dy.cols() == B,
             "MLP backward: dy is " << dy.rows() << "x" << dy.cols() << ", expected " << shape_.output << "x" << B);
  if (dx)
    MASA_CHECK(dx->rows() == shape_.input && dx->cols() == B,
               "MLP backward: dx is " << dx->rows() << "x" << dx->cols() << ", expected " << shape_.input << "x" << B);
}

template <typename S>
void Mlp<S>::backward(const ConstMatRef<S>& dy, MatRef<S>* dx) {
  checkBackward(dy, dx);
  const int B = batch_;
  if (B == 0) return;
  if constexpr (kFused) {
    const auto start = std::chrono::steady_clock::now();
    backwardFused(dy, dx, true);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    chunk_tuner_.record(B, backwardColumnsPerThread(B), forward_seconds_ + seconds);
  } else
    backwardGeneric(dy, dx, true);
}

template <typename S>
void Mlp<S>::inputGradient(const ConstMatRef<S>& dy, MatRef<S> dx) {
  checkBackward(dy, &dx);
  if (batch_ == 0) return;
  // (Not timed for the chunk tuner: it compares training steps, forward and full backward.)
  if constexpr (kFused)
    backwardFused(dy, &dx, false);
  else
    backwardGeneric(dy, &dx, false);
}

// ---- generic engine: one GemmWorkspace product per matrix, elementwise passes separate ----

template <typename S>
void Mlp<S>::forwardGeneric(const S* x, Index ldx, int B) {
  const S* prev = x;
  Index ld_prev = ldx;
  for (size_t k = 0; k < layers_.size(); ++k) {
    const Layer& l = layers_[k];
    auto W = std::as_const(*params_).value(l.w_offset, l.out, l.in);
    auto b = std::as_const(*params_).value(l.b_offset, l.out, 1);
    Mat<S>& y_store = y_[k];
    gemm_.run(plans_[3 * k], false, false, l.out, B, l.in, W.data(), l.out, prev, ld_prev, y_store.data(),
              y_store.rows(), false);
    auto y = y_store.topLeftCorner(l.out, B);
    y.colwise() += b.col(0);
    activate<S>(l.act, y, y);
    prev = y_store.data();
    ld_prev = y_store.rows();
  }
}

template <typename S>
void Mlp<S>::backwardGeneric(const ConstMatRef<S>& dy, MatRef<S>* dx, bool weight_grads) {
  const int B = batch_;
  // dz of the current layer lives in `cur`; W^T dz goes to `next`, which becomes the previous
  // layer's dz in place. The two scratch buffers swap roles each layer. Derivatives are taken
  // from y (ReLU's y > 0 is z > 0).
  Mat<S>* cur = &grad_a_;
  Mat<S>* next = &grad_b_;
  const int L = numLayers();
  {
    const Layer& l = layers_[L - 1];
    auto y = y_[L - 1].topLeftCorner(l.out, B);
    activateBackward<S>(l.act, y, y, dy, cur->topLeftCorner(l.out, B));
  }
  for (int k = L - 1; k >= 0; --k) {
    const Layer& l = layers_[k];
    auto dz = cur->topLeftCorner(l.out, B);
    auto W = std::as_const(*params_).value(l.w_offset, l.out, l.in);
    const Mat<S>& prev = k == 0 ? input_ : y_[k - 1];
    // dW += dz prev^T, db += row sums of dz, dprev = W^T dz.
    if (weight_grads) {
      gemm_.run(plans_[3 * k + 1], false, true, l.out, l.in, B, dz.data(), cur->rows(), prev.data(), prev.rows(),
                params_->grad(l.w_offset, l.out, l.in).data(), l.out, true);
      params_->grad(l.b_offset, l.out, 1).col(0) += dz.rowwise().sum();
    }
    if (k == 0) {
      if (dx)
        gemm_.run(plans_[3 * k + 2], true, false, l.in, B, l.out, W.data(), l.out, dz.data(), cur->rows(), dx->data(),
                  dx->outerStride(), false);
      break;
    }
    auto dprev = next->topLeftCorner(l.in, B);
    gemm_.run(plans_[3 * k + 2], true, false, l.in, B, l.out, W.data(), l.out, dz.data(), cur->rows(), dprev.data(),
              next->rows(), false);
    const Layer& lp = layers_[k - 1];
    auto y_prev = y_[k - 1].topLeftCorner(lp.out, B);
    activateBackward<S>(lp.act, y_prev, y_prev, dprev, dprev);
    std::swap(cur, next);
  }
}

// ---- fused engine (float, AVX-512 or AVX2): chunks of the batch through all layers, over threads ----
//
// Forward chunks are handed out dynamically: a thread whose core is shared with another process
// takes fewer of them instead of holding the other one up at the end of the step (each column's
// result is the same whoever computes it). Backward chunks are split statically: they are summed
// into per-thread gradients, and the summation order must not depend on timing.

template <typename S>
void Mlp<S>::forwardFused(const S* x, Index ldx, int B, bool keep_input) {
  if constexpr (kFused) {
    const S* values = std::as_const(*params_).values().data();
    const int L = numLayers();
    const int width = chunk_tuner_.width(backwardColumnsPerThread(B));
    auto chunk = [&](int j0) {
      const int n = std::min(width, B - j0);
      const S* in = x + j0 * ldx;
      Index ld_in = ldx;
      if (keep_input) {
        using Strided = Eigen::Map<const Mat<S>, 0, Eigen::OuterStride<>>;
        input_.middleCols(j0, n) = Strided(in, shape_.input, n, Eigen::OuterStride<>(ldx));
        in = input_.data() + j0 * input_.rows();
        ld_in = input_.rows();
      }
      for (int k = 0; k < L; ++k) {
        const Layer& l = layers_[k];
        const Index ld_out = y_[k].rows();
        S* out = y_[k].data() + j0 * ld_out;
        dense::forward(values + l.w_offset, l.out, l.out, l.in, values + l.b_offset, l.act, in, ld_in, out, ld_out, n);
        in = out;
        ld_in = ld_out;
      }
    };
    const int chunks = (B + width - 1) / width;
    const int threads = std::min(chunks, threadsFor(B, kMinForwardColumnsPerThread));
    if (threads <= 1) {
      for (int c = 0; c < chunks; ++c) chunk(c * width);
      return;
    }
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int c = 0; c < chunks; ++c) chunk(c * width);
  }
}

template <typename S>
void Mlp<S>::inferPacked(const S* x, Index ldx, int n) {
  if constexpr (kFused) {
    const S* values = std::as_const(*params_).values().data();
    Vec<S>& pack = inference_pack_[n - 1];
    if (pack.size() == 0) {
      Index size = 0;
      for (const Layer& l : layers_) size += dense::packedSize(l.out, l.in);
      pack.resize(size);
      S* at = pack.data();
      for (const Layer& l : layers_) {
        dense::packForward(values + l.w_offset, l.out, l.out, l.in, n, at);
        at += dense::packedSize(l.out, l.in);
      }
    }
    const S* w = pack.data();
    const S* in = x;
    Index ld_in = ldx;
    for (int k = 0; k < numLayers(); ++k) {
      const Layer& l = layers_[k];
      const Index ld_out = y_[k].rows();
      dense::forwardPacked(w, l.out, l.in, values + l.b_offset, l.act, in, ld_in, y_[k].data(), ld_out, n);
      w += dense::packedSize(l.out, l.in);
      in = y_[k].data();
      ld_in = ld_out;
    }
  }
}

template <typename S>
void Mlp<S>::backwardFused(const ConstMatRef<S>& dy, MatRef<S>* dx, bool weight_grads) {
  if constexpr (kFused) {
    const int B = batch_;
    const int L = numLayers();
    const S* values = std::as_const(*params_).values().data();
    // W^T of every layer whose input gradient is needed, packed by `part` of `parts` threads.
    auto pack_transposes = [&](int part, int parts) {
      for (int k = dx ? 0 : 1; k < L; ++k) {
        const Layer& l = layers_[k];
        // Rotated per layer so that the odd panels of each layer do not all fall to one thread.
        dense::pack(values + l.w_offset, l.out, true, l.in, l.out, packed_t_.data() + packed_t_offset_[k],
                    (part + k) % parts, parts);
      }
    };
    // Columns [j0, j0 + n) through every layer, on thread t's scratch, into gradient `grad`.
    auto chunk = [&](int j0, int n, int t, S* grad) {
      Mat<S>& scratch = scratch_[t];
      const Index ld_s = scratch.rows();
      S* buffers[2] = {scratch.data(), scratch.data() + ld_s * (scratch.cols() / 2)};
      int free_buffer = 0;
      const Layer& last = layers_[L - 1];
      const S* g = dy.data() + j0 * dy.outerStride();
      Index ld_g = dy.outerStride();
      if (last.act != Activation::kIdentity) {
        using Strided = Eigen::Map<Mat<S>, 0, Eigen::OuterStride<>>;
        using ConstStrided = Eigen::Map<const Mat<S>, 0, Eigen::OuterStride<>>;
        const Index ld_y = y_[L - 1].rows();
        const ConstStrided y(y_[L - 1].data() + j0 * ld_y, last.out, n, Eigen::OuterStride<>(ld_y));
        activateBackward<S>(last.act, y, y, ConstStrided(g, last.out, n, Eigen::OuterStride<>(ld_g)),
                            Strided(buffers[0], last.out, n, Eigen::OuterStride<>(ld_s)));
        g = buffers[0];
        ld_g = ld_s;
        free_buffer = 1;
      }
      for (int k = L - 1; k >= 0; --k) {
        const Layer& l = layers_[k];
        const Index ld_x = k == 0 ? input_.rows() : y_[k - 1].rows();
        const S* x_k = (k == 0 ? input_.data() : y_[k - 1].data()) + j0 * ld_x;
        if (weight_grads)
          dense::weightGrad(l.out, l.in, n, g, ld_g, x_k, ld_x, grad + (l.w_offset - param_begin_),
                            grad + (l.b_offset - param_begin_));
        const S* packed = packed_t_.data() + packed_t_offset_[k];
        if (k > 0) {
          S* d = buffers[free_buffer];
          dense::inputGrad(packed, l.in, l.out, g, ld_g, layers_[k - 1].act, x_k, ld_x, d, ld_s, n);
          g = d;
          ld_g = ld_s;
          free_buffer ^= 1;
        } else if (dx) {
          dense::inputGrad(packed, l.in, l.out, g, ld_g, Activation::kIdentity, nullptr, 0,
                           dx->data() + j0 * dx->outerStride(), dx->outerStride(), n);
        }
      }
    };
    // Blocks [b0, b1) in chunks of `width` columns. Whatever the width, each layer's weight
    // gradient receives the same block sums in the same order (dense::weightGrad sums a chunk
    // block by block), so the width changes no bit of the result.
    const int width = chunk_tuner_.width(backwardColumnsPerThread(B));
    auto blocks_in_chunks = [&](int b0, int b1, int t, S* grad) {
      for (int b = b0; b < b1; b += width / kBlock) {
        const int j0 = b * kBlock;
        chunk(j0, std::min({width, (b1 - b) * kBlock, B - j0}), t, grad);
      }
    };
    S* grads = params_->grads().data() + param_begin_;
    const int blocks = (B + kBlock - 1) / kBlock;
    const int threads = std::min({blocks, threadsFor(B, kMinBackwardColumnsPerThread), static_cast<int>(scratch_.size())});
    if (threads <= 1) {
      pack_transposes(0, 1);
      blocks_in_chunks(0, blocks, 0, grads);
      return;
    }
    const int P = numParams();
#pragma omp parallel num_threads(threads)
    {
      // Thread 0 accumulates into the parameter set, the others into zeroed partials summed below.
      const int t = omp_get_thread_num(), nt = omp_get_num_threads();
      S* grad = t == 0 ? grads : grad_partial_[t - 1].data();
      if (t > 0 && weight_grads) grad_partial_[t - 1].setZero();
      // The packing is a serial pass over every weight otherwise (5% of a 1024-column step on two
      // threads); each panel is written by one thread, so the packed bytes are the same.
      pack_transposes(t, nt);
#pragma omp barrier
      // Static: which blocks a thread sums must not depend on timing, or the float sums (and so
      // the whole run) would differ between runs of the same seed. Contiguous runs of blocks,
      // the first (blocks % nt) threads one more (OpenMP's static schedule, as before chunks
      // could be wider than a block).
      const int per = blocks / nt, extra = blocks % nt;
      const int b0 = t * per + std::min(t, extra);
      blocks_in_chunks(b0, b0 + per + (t < extra ? 1 : 0), t, grad);
      if (weight_grads) {  // (the same on every thread, so all of them or none meet the barrier)
#pragma omp barrier
        // (every partial is complete)
        const auto [p0, p1] = columnRange(P, t, nt);
        Eigen::Map<Vec<S>> total(grads + p0, p1 - p0);
        for (int u = 1; u < nt; ++u) total += grad_partial_[u - 1].segment(p0, p1 - p0);
      }
    }
  }
}

template class Mlp<float>;
template class Mlp<double>;

}  // namespace masa::nn
