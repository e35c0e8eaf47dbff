// A sparse linear map y = M x applied column by column to a batch (features x batch).
//
// Symmetry transforms are signed permutations plus small rotation blocks: every row has one to
// four nonzeros. Storing them row-compressed and applying them in a tight loop is cheaper than a
// general sparse product and allocates nothing.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/core/check.hpp"
#include "common/core/types.hpp"

namespace masa::sym {

struct Triplet {
  int row;
  int col;
  double value;
};

class SparseMap {
 public:
  SparseMap() = default;
  // Duplicate (row, col) pairs are summed; exact zeros are dropped.
  SparseMap(int rows, int cols, const std::vector<Triplet>& triplets);

  static SparseMap identity(int n);
  static SparseMap fromDense(const Eigen::MatrixXd& dense, double zero_tol = 0.0);

  int rows() const { return rows_; }
  int cols() const { return cols_; }
  int nonZeros() const { return static_cast<int>(col_.size()); }

  // out = M * in. `out` must not alias `in`. Both are features x batch with equal batch size.
  template <typename S>
  void apply(const ConstMatRef<S>& in, MatRef<S> out) const;
  // out += M * in.
  template <typename S>
  void applyAdd(const ConstMatRef<S>& in, MatRef<S> out) const;

  SparseMap transpose() const;
  // this * rhs (apply rhs first).
  SparseMap compose(const SparseMap& rhs) const;
  Eigen::MatrixXd toDense() const;

  // Row-compressed storage, read-only access for callers that fuse loops.
  const std::vector<int>& rowStart() const { return row_start_; }
  const std::vector<int>& colIndex() const { return col_; }
  const std::vector<double>& values() const { return value_d_; }

 private:
  template <typename S>
  const std::vector<S>& valuesAs() const;

  int rows_ = 0;
  int cols_ = 0;
  std::vector<int> row_start_{0};
  std::vector<int> col_;
  std::vector<double> value_d_;
  std::vector<float> value_f_;
  // Every row has exactly one nonzero (a signed permutation or a selection): entry r is row r, and
  // apply() runs one branch-free loop (the robot runner's agent stack, a few hundred rows a step).
  bool one_per_row_ = false;
};

template <typename S>
void SparseMap::apply(const ConstMatRef<S>& in, MatRef<S> out) const {
  MASA_CHECK(in.rows() == cols_, "input has " << in.rows() << " rows, map expects " << cols_);
  MASA_CHECK(out.rows() == rows_, "output has " << out.rows() << " rows, map gives " << rows_);
  MASA_CHECK(in.cols() == out.cols(), "batch sizes differ: " << in.cols() << " vs " << out.cols());
  MASA_CHECK(in.data() != out.data() || in.size() == 0, "apply() does not support aliasing");
  const std::vector<S>& v = valuesAs<S>();
  for (Eigen::Index b = 0; b < in.cols(); ++b) {
    const S* x = in.col(b).data();
    S* y = out.col(b).data();
    if (one_per_row_) {  // S(0) + ...: the same bits as the general loop, -0 included
      for (int r = 0; r < rows_; ++r) y[r] = S(0) + v[r] * x[col_[r]];
      continue;
    }
    for (int r = 0; r < rows_; ++r) {
      S acc = S(0);
      for (int k = row_start_[r]; k < row_start_[r + 1]; ++k) acc += v[k] * x[col_[k]];
      y[r] = acc;
    }
  }
}

template <typename S>
void SparseMap::applyAdd(const ConstMatRef<S>& in, MatRef<S> out) const {
  MASA_CHECK(in.rows() == cols_, "input has " << in.rows() << " rows, map expects " << cols_);
  MASA_CHECK(out.rows() == rows_, "output has " << out.rows() << " rows, map gives " << rows_);
  MASA_CHECK(in.cols() == out.cols(), "batch sizes differ: " << in.cols() << " vs " << out.cols());
  const std::vector<S>& v = valuesAs<S>();
  for (Eigen::Index b = 0; b < in.cols(); ++b) {
    const S* x = in.col(b).data();
    S* y = out.col(b).data();
    if (one_per_row_) {
      for (int r = 0; r < rows_; ++r) y[r] += S(0) + v[r] * x[col_[r]];
      continue;
    }
    for (int r = 0; r < rows_; ++r) {
      S acc = S(0);
      for (int k = row_start_[r]; k < row_start_[r + 1]; ++k) acc += v[k] * x[col_[k]];
      y[r] += acc;
    }
  }
}

template <>
inline const std::vector<double>& SparseMap::valuesAs<double>() const {
  return value_d_;
}
template <>
inline const std::vector<float>& SparseMap::valuesAs<float>() const {
  return value_f_;
}

}  // namespace masa::sym
