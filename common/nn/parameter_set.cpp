// Flat parameter storage: segments are laid out back to back in reservation order.
#include "common/nn/parameter_set.hpp"

#include <algorithm>
#include <limits>

#include "common/core/check.hpp"

namespace masa::nn {

template <typename S>
int ParameterSet<S>::reserve(const std::string& name, int rows, int cols) {
  MASA_CHECK(!finalized_, "cannot reserve '" << name << "' after finalize()");
  MASA_CHECK(rows > 0 && cols > 0, "segment '" << name << "' has shape " << rows << "x" << cols);
  MASA_CHECK(static_cast<long long>(rows) * cols <= std::numeric_limits<int>::max() - size_,
             "segment '" << name << "' overflows the parameter index");
  for (const auto& s : segments_) MASA_CHECK(s.name != name, "duplicate parameter name '" << name << "'");
  segments_.push_back(ParameterSegment{name, size_, rows, cols});
  size_ += rows * cols;
  return segments_.back().offset;
}

template <typename S>
void ParameterSet<S>::finalize() {
  if (finalized_) return;
  values_ = Vec<S>::Zero(size_);
  grads_ = Vec<S>::Zero(size_);
  finalized_ = true;
}

template <typename S>
const ParameterSegment& ParameterSet<S>::segment(const std::string& name) const {
  auto it = std::find_if(segments_.begin(), segments_.end(), [&](const ParameterSegment& s) { return s.name == name; });
  MASA_CHECK(it != segments_.end(), "unknown parameter segment '" << name << "'");
  return *it;
}

namespace {
void checkView(bool finalized, int size, int offset, int rows, int cols) {
  MASA_CHECK(finalized, "parameter views need finalize() first");
  const long long end = static_cast<long long>(offset) + static_cast<long long>(rows) * cols;
  MASA_CHECK(offset >= 0 && rows >= 0 && cols >= 0 && end <= size,
             "view at offset " << offset << " of " << rows << "x" << cols << " exceeds the " << size << " parameters");
}
}  // namespace

template <typename S>
Eigen::Map<Mat<S>> ParameterSet<S>::value(int offset, int rows, int cols) {
  checkView(finalized_, size_, offset, rows, cols);
  MASA_CHECK(!frozen_, "the parameters are frozen for inference and cannot be written");
  return Eigen::Map<Mat<S>>(values_.data() + offset, rows, cols);
}

template <typename S>
Eigen::Map<const Mat<S>> ParameterSet<S>::value(int offset, int rows, int cols) const {
  checkView(finalized_, size_, offset, rows, cols);
  return Eigen::Map<const Mat<S>>(values_.data() + offset, rows, cols);
}

template <typename S>
Eigen::Map<Mat<S>> ParameterSet<S>::grad(int offset, int rows, int cols) {
  checkView(finalized_, size_, offset, rows, cols);
  return Eigen::Map<Mat<S>>(grads_.data() + offset, rows, cols);
}

template class ParameterSet<float>;
template class ParameterSet<double>;

}  // namespace masa::nn
