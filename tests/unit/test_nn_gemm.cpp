#include <gtest/gtest.h>

#include <tuple>

#include "common/nn/gemm.hpp"

namespace masa::nn {
namespace {

// (trans_a, trans_b, m, n, k): small, single-column (GEMV path), and large enough to be blocked
// and split over threads.
using GemmCase = std::tuple<bool, bool, int, int, int>;

class GemmWorkspaceProduct : public ::testing::TestWithParam<GemmCase> {};

TEST_P(GemmWorkspaceProduct, MatchesEigenForStridedOperandsAndAccumulates) {
  const auto [ta, tb, m, n, k] = GetParam();
  // Operands live inside larger matrices so that leading dimensions differ from the row counts.
  const Mat<double> a_store = Mat<double>::Random((ta ? k : m) + 3, ta ? m : k);
  const Mat<double> b_store = Mat<double>::Random((tb ? n : k) + 2, tb ? k : n);
  const auto a = a_store.topRows(ta ? k : m);
  const auto b = b_store.topRows(tb ? n : k);
  const Mat<double> op_a = ta ? Mat<double>(a.transpose()) : Mat<double>(a);
  const Mat<double> op_b = tb ? Mat<double>(b.transpose()) : Mat<double>(b);
  const Mat<double> expected = op_a * op_b;

  GemmWorkspace<double> ws;
  const GemmPlan plan = GemmWorkspace<double>::plan(m, n, k);
  ws.reserve({plan});
  Mat<double> c_store = Mat<double>::Constant(m + 5, n, 7.0);
  ws.run(plan, ta, tb, m, n, k, a_store.data(), a_store.rows(), b_store.data(), b_store.rows(), c_store.data(),
         c_store.rows(), false);
  const double tol = 1e-12 * k;
  EXPECT_LT((c_store.topRows(m) - expected).cwiseAbs().maxCoeff(), tol);
  EXPECT_TRUE((c_store.bottomRows(5).array() == 7.0).all());  // rows past m untouched

  ws.run(plan, ta, tb, m, n, k, a_store.data(), a_store.rows(), b_store.data(), b_store.rows(), c_store.data(),
         c_store.rows(), true);
  EXPECT_LT((c_store.topRows(m) - 2 * expected).cwiseAbs().maxCoeff(), 2 * tol);
}

INSTANTIATE_TEST_SUITE_P(
    Shapes, GemmWorkspaceProduct,
    ::testing::Values(GemmCase{false, false, 5, 3, 4}, GemmCase{false, true, 5, 3, 4}, GemmCase{true, false, 5, 3, 4},
                      GemmCase{true, true, 5, 3, 4}, GemmCase{false, false, 37, 1, 29}, GemmCase{true, false, 37, 1, 29},
                      GemmCase{false, true, 37, 1, 29}, GemmCase{false, false, 200, 301, 150}, GemmCase{false, true, 100, 74, 900},
                      GemmCase{true, false, 74, 530, 400}, GemmCase{true, true, 63, 257, 129}));

TEST(GemmWorkspace, SmallerProductsReuseTheBuffersOfTheLargestPlan) {
  GemmWorkspace<float> ws;
  const GemmPlan plan = GemmWorkspace<float>::plan(64, 1000, 300);
  ws.reserve({plan});
  for (int n : {1000, 17, 400}) {
    const Mat<float> a = Mat<float>::Random(64, 300), b = Mat<float>::Random(300, n);
    Mat<float> c(64, n);
    ws.run(plan, false, false, 64, n, 300, a.data(), 64, b.data(), 300, c.data(), 64, false);
    EXPECT_LT((c - a * b).cwiseAbs().maxCoeff(), 1e-3f) << "n = " << n;
  }
}

}  // namespace
}  // namespace masa::nn
