// SparseMap against dense Eigen products on random data.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
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

// A signed permutation (one nonzero per row) takes apply()'s branch-free loop; the same rows inside
// a map with a two-nonzero row take the general one. Their bits agree, signed zeros included.
TEST(SparseMapTest, OneNonzeroPerRowGivesTheBitsOfTheGeneralLoop) {
  const std::vector<Triplet> perm{{0, 2, -1.0}, {1, 0, 1.0}, {2, 3, -0.5}, {3, 1, 1.0}};
  std::vector<Triplet> general = perm;
  general.push_back({4, 0, 1.0});
  general.push_back({4, 1, 1.0});
  const SparseMap fast(4, 4, perm), slow(5, 4, general);
  Eigen::MatrixXf x = Eigen::MatrixXf::Random(4, 3);
  x(0, 0) = -0.f;  // v * x = -0 in row 1 (and +0 in rows with v < 0)
  x(2, 1) = 0.f;
  Eigen::MatrixXf y_fast(4, 3), y_slow(5, 3), add_fast = Eigen::MatrixXf::Constant(4, 3, -0.f),
      add_slow = Eigen::MatrixXf::Constant(5, 3, -0.f);
  fast.apply<float>(x, y_fast);
  slow.apply<float>(x, y_slow);
  fast.applyAdd<float>(x, add_fast);
  slow.applyAdd<float>(x, add_slow);
  for (int j = 0; j < 3; ++j)
    for (int r = 0; r < 4; ++r) {
      EXPECT_EQ(std::bit_cast<uint32_t>(y_fast(r, j)), std::bit_cast<uint32_t>(y_slow(r, j))) << r << "," << j;
      EXPECT_EQ(std::bit_cast<uint32_t>(add_fast(r, j)), std::bit_cast<uint32_t>(add_slow(r, j))) << r << "," << j;
    }
  EXPECT_EQ(y_fast(1, 0), 0.f);
  EXPECT_FALSE(std::signbit(y_fast(1, 0)));  // 0 + (-0) = +0, as the general loop's sum gives
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
