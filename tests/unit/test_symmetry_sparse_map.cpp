// SparseMap against dense Eigen products on random data.
#include <gtest/gtest.h>

#include <random>

#include "common/symmetry/sparse_map.hpp"

namespace masa::sym {
namespace {

// Random triplets with repeated (row, col) pairs, so summing duplicates is exercised too.
SparseMap randomMap(int rows, int cols, int nnz, Rng& rng) {
  std::uniform_int_distribution<int> row(0, rows - 1), col(0, cols - 1);
  std::normal_distribution<double> value;
  std::vector<Triplet> t;
  for (int k = 0; k < nnz; ++k) t.push_back({row(rng), col(rng), value(rng)});
  t.push_back(t.front());
  return SparseMap(rows, cols, t);
}

TEST(SparseMapTest, DuplicatesAreSummedAndZerosDropped) {
  const SparseMap m(2, 3, {{0, 1, 1.5}, {0, 1, 2.0}, {1, 2, 0.0}, {1, 0, -1.0}, {1, 0, 1.0}});
  EXPECT_EQ(m.nonZeros(), 1);
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(2, 3);
  expected(0, 1) = 3.5;
  EXPECT_EQ(m.toDense(), expected);
}

TEST(SparseMapTest, ApplyMatchesDenseProduct) {
  Rng rng(1);
  const SparseMap m = randomMap(7, 5, 20, rng);
  const Eigen::MatrixXd x = Eigen::MatrixXd::Random(5, 9);
  Eigen::MatrixXd y(7, 9);
  m.apply<double>(x, y);
  EXPECT_LT((y - m.toDense() * x).cwiseAbs().maxCoeff(), 1e-14);

  const Eigen::MatrixXf xf = x.cast<float>();
  Eigen::MatrixXf yf(7, 9);
  m.apply<float>(xf, yf);
  EXPECT_LT((yf - (m.toDense() * x).cast<float>()).cwiseAbs().maxCoeff(), 1e-5f);
}

TEST(SparseMapTest, ApplyAddAccumulatesIntoOutput) {
  Rng rng(2);
  const SparseMap m = randomMap(4, 6, 10, rng);
  const Eigen::MatrixXd x = Eigen::MatrixXd::Random(6, 3);
  const Eigen::MatrixXd y0 = Eigen::MatrixXd::Random(4, 3);
  Eigen::MatrixXd y = y0;
  m.applyAdd<double>(x, y);
  EXPECT_LT((y - (y0 + m.toDense() * x)).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(SparseMapTest, ApplyRejectsWrongShapes) {
  const SparseMap m = SparseMap::identity(3);
  Eigen::MatrixXd x = Eigen::MatrixXd::Ones(4, 2), y(3, 2);
  EXPECT_THROW(m.apply<double>(x, y), std::invalid_argument);
  Eigen::MatrixXd x3 = Eigen::MatrixXd::Ones(3, 2), y_batch(3, 1);
  EXPECT_THROW(m.apply<double>(x3, y_batch), std::invalid_argument);
}

TEST(SparseMapTest, TransposeMatchesDenseTranspose) {
  Rng rng(3);
  const SparseMap m = randomMap(6, 4, 12, rng);
  const SparseMap t = m.transpose();
  EXPECT_EQ(t.rows(), 4);
  EXPECT_EQ(t.cols(), 6);
  EXPECT_EQ(t.toDense(), Eigen::MatrixXd(m.toDense().transpose()));
}

TEST(SparseMapTest, ComposeMatchesDenseProduct) {
  Rng rng(4);
  const SparseMap a = randomMap(5, 8, 15, rng);
  const SparseMap b = randomMap(8, 3, 12, rng);
  const SparseMap ab = a.compose(b);
  EXPECT_EQ(ab.rows(), 5);
  EXPECT_EQ(ab.cols(), 3);
  EXPECT_LT((ab.toDense() - a.toDense() * b.toDense()).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_THROW(b.compose(b), std::invalid_argument);
}

TEST(SparseMapTest, FromDenseAndIdentityRoundTrip) {
  Eigen::MatrixXd d(2, 3);
  d << 0, 1e-3, 2, -1, 0, 0;
  EXPECT_EQ(SparseMap::fromDense(d).toDense(), d);
  EXPECT_EQ(SparseMap::fromDense(d, 1e-2).nonZeros(), 2);
  EXPECT_EQ(SparseMap::identity(4).toDense(), Eigen::MatrixXd::Identity(4, 4));
}

}  // namespace
}  // namespace masa::sym
