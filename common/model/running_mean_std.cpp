#include "common/model/running_mean_std.hpp"

#include <algorithm>
#include <cmath>
#include <istream>
#include <ostream>
#include <stdexcept>

#include "common/core/binary_io.hpp"
#include "common/core/check.hpp"

namespace masa::model {

template <typename S>
RunningMeanStd<S>::RunningMeanStd(int dim, double epsilon)
    : dim_(dim),
      epsilon_(epsilon),
      count_(0.0),
      mean_(Eigen::VectorXd::Zero(dim)),
      var_(Eigen::VectorXd::Ones(dim)) {
  MASA_CHECK(dim > 0, "normalizer dimension must be positive, got " << dim);
  refreshEffective();
}

template <typename S>
void RunningMeanStd<S>::setSymmetry(const std::vector<sym::SparseMap>& transforms, const std::vector<int>& classes) {
  MASA_CHECK(static_cast<int>(classes.size()) == dim_, "classes has " << classes.size() << " entries, dim " << dim_);
  for (const auto& t : transforms)
    MASA_CHECK(t.rows() == dim_ && t.cols() == dim_, "transform is " << t.rows() << "x" << t.cols() << ", dim " << dim_);
  transforms_ = transforms;
  classes_ = classes;
  refreshEffective();
}

template <typename S>
void RunningMeanStd<S>::update(const ConstMatRef<S>& batch) {
  MASA_CHECK(batch.rows() == dim_, "batch has " << batch.rows() << " rows, normalizer dim " << dim_);
  if (batch.cols() == 0) return;
  mergeMoments(batchMoments(batch));
}

template <typename S>
Eigen::VectorXd RunningMeanStd<S>::batchMoments(const ConstMatRef<S>& batch) {
  MASA_CHECK(batch.rows() == dim_, "batch has " << batch.rows() << " rows, normalizer dim " << dim_);
  // One pass of sums in double over the batch, or over its whole orbit when symmetric.
  Eigen::VectorXd moments = Eigen::VectorXd::Zero(2 * dim_ + 1);
  auto sum = moments.segment(0, dim_);
  auto sum_sq = moments.segment(dim_, dim_);
  auto accumulate = [&](const auto& x) {
    for (Eigen::Index b = 0; b < x.cols(); ++b)
      for (int d = 0; d < dim_; ++d) {
        const double v = static_cast<double>(x(d, b));
        sum(d) += v;
        sum_sq(d) += v * v;
      }
  };
  double n = static_cast<double>(batch.cols());
  if (transforms_.empty()) {
    accumulate(batch);
  } else if (batch.cols() > 0) {
    if (orbit_scratch_.cols() < batch.cols()) orbit_scratch_.resize(dim_, batch.cols());
    auto y = orbit_scratch_.leftCols(batch.cols());
    for (const auto& t : transforms_) {
      t.template apply<S>(batch, y);
      accumulate(y);
    }
    n *= static_cast<double>(transforms_.size());
  }
  moments(2 * dim_) = n;
  return moments;
}

template <typename S>
void RunningMeanStd<S>::mergeMoments(const Eigen::VectorXd& moments) {
  MASA_CHECK(moments.size() == 2 * dim_ + 1, "moments have " << moments.size() << " entries, normalizer dim " << dim_);
  const double n = moments(2 * dim_);
  if (n <= 0) return;
  const Eigen::VectorXd batch_mean = moments.segment(0, dim_) / n;
  const Eigen::VectorXd batch_var = (moments.segment(dim_, dim_) / n - batch_mean.cwiseAbs2()).cwiseMax(0.0);
  const double total = count_ + n;
  const Eigen::VectorXd delta = batch_mean - mean_;
  mean_ += delta * (n / total);
  var_ = (var_ * count_ + batch_var * n + delta.cwiseAbs2() * (count_ * n / total)) / total;
  count_ = total;
  refreshEffective();
}

template <typename S>
void RunningMeanStd<S>::refreshEffective() {
  mean_eff_ = mean_;
  var_eff_ = var_;
  if (!transforms_.empty()) {
    // Project the mean onto the subspace fixed by every T_i.
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(dim_, 1), tm(dim_, 1);
    for (const auto& t : transforms_) {
      t.template apply<double>(mean_, tm);
      m += tm;
    }
    mean_eff_ = m.col(0) / static_cast<double>(transforms_.size());
    // Tie variances within each orbit class (a rotating vector gets one variance).
    const int num_classes = classes_.empty() ? 0 : *std::max_element(classes_.begin(), classes_.end()) + 1;
    Eigen::VectorXd class_sum = Eigen::VectorXd::Zero(num_classes), class_n = Eigen::VectorXd::Zero(num_classes);
    for (int d = 0; d < dim_; ++d) {
      class_sum(classes_[d]) += var_(d);
      class_n(classes_[d]) += 1.0;
    }
    for (int d = 0; d < dim_; ++d) var_eff_(d) = class_sum(classes_[d]) / class_n(classes_[d]);
  }
  shift_ = mean_eff_.cast<S>();
  const Eigen::VectorXd scale = (var_eff_.array() + epsilon_).sqrt();
  scale_ = scale.cast<S>();
  inv_scale_ = scale.cwiseInverse().cast<S>();
}

template <typename S>
void RunningMeanStd<S>::normalize(const ConstMatRef<S>& in, MatRef<S> out) const {
  MASA_CHECK(in.rows() == dim_ && out.rows() == dim_ && in.cols() == out.cols(), "normalize: shapes differ");
  out = (in.colwise() - shift_).array().colwise() * inv_scale_.array();
}

template <typename S>
void RunningMeanStd<S>::denormalize(const ConstMatRef<S>& in, MatRef<S> out) const {
  MASA_CHECK(in.rows() == dim_ && out.rows() == dim_ && in.cols() == out.cols(), "denormalize: shapes differ");
  out = (in.array().colwise() * scale_.array()).matrix().colwise() + shift_;
}

template <typename S>
void RunningMeanStd<S>::setMeanStd(const float* mean, const float* std) {
  for (int d = 0; d < dim_; ++d)
    MASA_CHECK(std::isfinite(mean[d]) && std::isfinite(std[d]) && std[d] > 0.0f,
               "setMeanStd: entry " << d << " has mean " << mean[d] << ", std " << std[d]);
  for (int d = 0; d < dim_; ++d) {
    const double sd = std[d];
    mean_(d) = mean[d];
    var_(d) = std::max(sd * sd - epsilon_, 0.0);  // so that save() keeps what is used
  }
  mean_eff_ = mean_;
  var_eff_ = var_;
  // The used shift and scale are exactly the broadcast values, not re-derived through var + eps.
  for (int d = 0; d < dim_; ++d) {
    shift_(d) = static_cast<S>(mean[d]);
    scale_(d) = static_cast<S>(std[d]);
    inv_scale_(d) = static_cast<S>(1.0 / static_cast<double>(std[d]));
  }
}

template <typename S>
void RunningMeanStd<S>::save(std::ostream& os) const {
  const int32_t d = dim_;
  io::writePod(os, d);
  io::writePod(os, count_);
  io::writeArray(os, mean_.data(), static_cast<std::size_t>(dim_));
  io::writeArray(os, var_.data(), static_cast<std::size_t>(dim_));
}

template <typename S>
void RunningMeanStd<S>::load(std::istream& is) {
  int32_t d = 0;
  if (!io::readPod(is, d)) throw std::runtime_error("normalizer state is truncated");
  if (d != dim_)
    throw std::runtime_error("normalizer state has dimension " + std::to_string(d) + ", expected " +
                             std::to_string(dim_));
  double count = 0;
  Eigen::VectorXd mean(dim_), var(dim_);
  const auto n = static_cast<std::size_t>(dim_);
  if (!io::readPod(is, count) || !io::readArray(is, mean.data(), n) || !io::readArray(is, var.data(), n)) throw std::runtime_error("normalizer state is truncated");
  count_ = count;
  mean_ = mean;
  var_ = var;
  refreshEffective();
}

template class RunningMeanStd<float>;
template class RunningMeanStd<double>;

}  // namespace masa::model
