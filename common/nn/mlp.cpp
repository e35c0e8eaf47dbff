// Batched MLP forward/backward on buffers that only grow, so steady-state training allocates nothing.
#include "common/nn/mlp.hpp"

#include <algorithm>
#include <cmath>

#include "common/core/check.hpp"

namespace masa::nn {

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
  z_.resize(layers_.size());
  y_.resize(layers_.size());
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
  int max_width = shape_.input;
  for (size_t k = 0; k < layers_.size(); ++k) {
    z_[k].resize(layers_[k].out, batch);
    y_[k].resize(layers_[k].out, batch);
    max_width = std::max(max_width, layers_[k].out);
  }
  input_.resize(shape_.input, batch);
  grad_a_.resize(max_width, batch);
  grad_b_.resize(max_width, batch);
  plans_.clear();
  for (const Layer& l : layers_) {
    plans_.push_back(GemmWorkspace<S>::plan(l.out, batch, l.in));
    plans_.push_back(GemmWorkspace<S>::plan(l.out, l.in, batch));
    plans_.push_back(GemmWorkspace<S>::plan(l.in, batch, l.out));
  }
  gemm_.reserve(plans_);
  capacity_ = batch;
  batch_ = -1;  // the caches of an earlier forward are gone
}

template <typename S>
Eigen::Block<Mat<S>> Mlp<S>::forward(const ConstMatRef<S>& x) {
  MASA_CHECK(params_->finalized(), "MLP forward before the parameter set is finalized");
  MASA_CHECK(x.rows() == shape_.input, "MLP forward: input has " << x.rows() << " rows, expected " << shape_.input);
  const int B = static_cast<int>(x.cols());
  reserve(B);
  input_.leftCols(B) = x;
  for (size_t k = 0; k < layers_.size(); ++k) {
    const Layer& l = layers_[k];
    auto W = params_->value(l.w_offset, l.out, l.in);
    auto b = params_->value(l.b_offset, l.out, 1);
    auto z = z_[k].leftCols(B);
    const Mat<S>& prev = k == 0 ? input_ : y_[k - 1];
    gemm_.run(plans_[3 * k], false, false, l.out, B, l.in, W.data(), l.out, prev.data(), prev.rows(), z.data(),
              z_[k].rows(), false);
    z.colwise() += b.col(0);
    activate<S>(l.act, z, y_[k].leftCols(B));
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
  // Works in y_ only (activation in place), reading x directly: backward is no longer valid.
  batch_ = -1;
  for (size_t k = 0; k < layers_.size(); ++k) {
    const Layer& l = layers_[k];
    auto W = params_->value(l.w_offset, l.out, l.in);
    auto b = params_->value(l.b_offset, l.out, 1);
    auto y = y_[k].leftCols(B);
    const S* prev = k == 0 ? x.data() : y_[k - 1].data();
    const Eigen::Index ld_prev = k == 0 ? x.outerStride() : y_[k - 1].rows();
    gemm_.run(plans_[3 * k], false, false, l.out, B, l.in, W.data(), l.out, prev, ld_prev, y.data(), y_[k].rows(),
              false);
    y.colwise() += b.col(0);
    activate<S>(l.act, y, y);
  }
  return y_.back().block(0, 0, shape_.output, B);
}

template <typename S>
void Mlp<S>::backward(const ConstMatRef<S>& dy, MatRef<S>* dx) {
  const int B = batch_;
  MASA_CHECK(B >= 0, "MLP backward needs a forward() first (infer() does not keep caches)");
  MASA_CHECK(dy.rows() == shape_.output && dy.cols() == B,
             "MLP backward: dy is " << dy.rows() << "x" << dy.cols() << ", expected " << shape_.output << "x" << B);
  if (dx)
    MASA_CHECK(dx->rows() == shape_.input && dx->cols() == B,
               "MLP backward: dx is " << dx->rows() << "x" << dx->cols() << ", expected " << shape_.input << "x" << B);

  // dz of the current layer lives in `cur`; W^T dz goes to `next`, which becomes the previous
  // layer's dz in place. The two scratch buffers swap roles each layer.
  Mat<S>* cur = &grad_a_;
  Mat<S>* next = &grad_b_;
  const int L = numLayers();
  if (B == 0) return;
  {
    const Layer& l = layers_[L - 1];
    activateBackward<S>(l.act, z_[L - 1].leftCols(B), y_[L - 1].leftCols(B), dy, cur->topLeftCorner(l.out, B));
  }
  for (int k = L - 1; k >= 0; --k) {
    const Layer& l = layers_[k];
    auto dz = cur->topLeftCorner(l.out, B);
    auto W = params_->value(l.w_offset, l.out, l.in);
    const Mat<S>& prev = k == 0 ? input_ : y_[k - 1];
    // dW += dz prev^T, db += row sums of dz, dprev = W^T dz.
    gemm_.run(plans_[3 * k + 1], false, true, l.out, l.in, B, dz.data(), cur->rows(), prev.data(), prev.rows(),
              params_->grad(l.w_offset, l.out, l.in).data(), l.out, true);
    params_->grad(l.b_offset, l.out, 1).col(0) += dz.rowwise().sum();
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
    activateBackward<S>(lp.act, z_[k - 1].leftCols(B), y_[k - 1].leftCols(B), dprev, dprev);
    std::swap(cur, next);
  }
}

template class Mlp<float>;
template class Mlp<double>;

}  // namespace masa::nn
