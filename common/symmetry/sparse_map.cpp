#include "common/symmetry/sparse_map.hpp"

#include <algorithm>
#include <map>

namespace masa::sym {

SparseMap::SparseMap(int rows, int cols, const std::vector<Triplet>& triplets) : rows_(rows), cols_(cols) {
  MASA_CHECK(rows >= 0 && cols >= 0, "negative size " << rows << "x" << cols);
  std::vector<std::map<int, double>> by_row(rows);
  for (const Triplet& t : triplets) {
    MASA_CHECK(t.row >= 0 && t.row < rows, "row " << t.row << " out of range [0, " << rows << ")");
    MASA_CHECK(t.col >= 0 && t.col < cols, "col " << t.col << " out of range [0, " << cols << ")");
    by_row[t.row][t.col] += t.value;
  }
  row_start_.assign(1, 0);
  for (const auto& row : by_row) {
    for (const auto& [c, v] : row) {
      if (v == 0.0) continue;
      col_.push_back(c);
      value_d_.push_back(v);
    }
    row_start_.push_back(static_cast<int>(col_.size()));
  }
  value_f_.assign(value_d_.begin(), value_d_.end());
  one_per_row_ = nonZeros() == rows_;
  for (int r = 0; r < rows_ && one_per_row_; ++r) one_per_row_ = row_start_[r] == r;
}

SparseMap SparseMap::identity(int n) {
  std::vector<Triplet> t;
  t.reserve(n);
  for (int i = 0; i < n; ++i) t.push_back({i, i, 1.0});
  return SparseMap(n, n, t);
}

SparseMap SparseMap::fromDense(const Eigen::MatrixXd& dense, double zero_tol) {
  std::vector<Triplet> t;
  for (int r = 0; r < dense.rows(); ++r)
    for (int c = 0; c < dense.cols(); ++c)
      if (std::abs(dense(r, c)) > zero_tol) t.push_back({r, c, dense(r, c)});
  return SparseMap(static_cast<int>(dense.rows()), static_cast<int>(dense.cols()), t);
}

SparseMap SparseMap::transpose() const {
  std::vector<Triplet> t;
  t.reserve(col_.size());
  for (int r = 0; r < rows_; ++r)
    for (int k = row_start_[r]; k < row_start_[r + 1]; ++k) t.push_back({col_[k], r, value_d_[k]});
  return SparseMap(cols_, rows_, t);
}

SparseMap SparseMap::compose(const SparseMap& rhs) const {
  MASA_CHECK(cols_ == rhs.rows_, "cannot compose " << rows_ << "x" << cols_ << " with " << rhs.rows_ << "x"
                                                   << rhs.cols_);
  std::vector<Triplet> t;
  for (int r = 0; r < rows_; ++r)
    for (int k = row_start_[r]; k < row_start_[r + 1]; ++k) {
      const int mid = col_[k];
      for (int j = rhs.row_start_[mid]; j < rhs.row_start_[mid + 1]; ++j)
        t.push_back({r, rhs.col_[j], value_d_[k] * rhs.value_d_[j]});
    }
  return SparseMap(rows_, rhs.cols_, t);
}

Eigen::MatrixXd SparseMap::toDense() const {
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(rows_, cols_);
  for (int r = 0; r < rows_; ++r)
    for (int k = row_start_[r]; k < row_start_[r + 1]; ++k) d(r, col_[k]) = value_d_[k];
  return d;
}

}  // namespace masa::sym
