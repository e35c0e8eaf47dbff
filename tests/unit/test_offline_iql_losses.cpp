// IQL's losses against hand-computed cases and their gradients against finite differences.
#include <gtest/gtest.h>

#include <cmath>

#include "learner/offline/iql_losses.hpp"
#include "model_test_support.hpp"

namespace masa::offline {
namespace {

Mat<double> row(std::initializer_list<double> v) {
  Mat<double> m(1, static_cast<Eigen::Index>(v.size()));
  Eigen::Index k = 0;
  for (double x : v) m(0, k++) = x;
  return m;
}

TEST(IqlLosses, ExpectileWeighsUnderEstimatesByTauAndOverEstimatesByOneMinusTau) {
  // u = target - value = (2, -1, 0): weights 0.7, 0.3, 0.7 (u = 0 counts as not negative).
  const Mat<double> value = row({1, 2, 0}), target = row({3, 1, 0});
  Mat<double> dv(1, 3);
  const double loss = expectileLoss<double>(value, target, 0.7, dv);
  EXPECT_NEAR(loss, (0.7 * 4 + 0.3 * 1 + 0.0) / 3, 1e-15);
  // dL/dv = -2 w u / B
  EXPECT_NEAR(dv(0, 0), -2 * 0.7 * 2 / 3, 1e-15);
  EXPECT_NEAR(dv(0, 1), -2 * 0.3 * -1 / 3, 1e-15);
  EXPECT_EQ(dv(0, 2), 0.0);
}

TEST(IqlLosses, ExpectileAtOneHalfIsHalfTheMeanSquaredError) {
  Rng rng(1);
  const Mat<double> v = test::randomMatrix<double>(1, 9, rng), t = test::randomMatrix<double>(1, 9, rng);
  Mat<double> dv(1, 9);
  EXPECT_NEAR(expectileLoss<double>(v, t, 0.5, dv), 0.5 * (t - v).squaredNorm() / 9, 1e-14);
  EXPECT_LT((dv - (v - t) / 9).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(IqlLosses, ExpectileGradientMatchesFiniteDifferences) {
  Rng rng(2);
  Mat<double> v = test::randomMatrix<double>(1, 7, rng);
  const Mat<double> t = test::randomMatrix<double>(1, 7, rng);
  Mat<double> dv(1, 7), scratch(1, 7);
  expectileLoss<double>(v, t, 0.8, dv);
  Eigen::Map<Vec<double>> x(v.data(), v.size());
  const Vec<double> analytic = Eigen::Map<const Vec<double>>(dv.data(), dv.size());
  const auto r = test::checkGradient(x, analytic, [&] { return expectileLoss<double>(v, t, 0.8, scratch); });
  EXPECT_LT(r.max_relative_error, 1e-6);
}

TEST(IqlLosses, AdvantageWeightsAreExponentialAndClipped) {
  const Mat<double> adv = row({0, 1, 10, -2, 1000});
  Mat<double> w(1, 5);
  advantageWeights<double>(adv, 3.0, 100.0, w);
  EXPECT_DOUBLE_EQ(w(0, 0), 1.0);
  EXPECT_NEAR(w(0, 1), std::exp(3.0), 1e-12);
  EXPECT_EQ(w(0, 2), 100.0);  // exp(30) clipped
  EXPECT_NEAR(w(0, 3), std::exp(-6.0), 1e-15);
  EXPECT_EQ(w(0, 4), 100.0);  // exp overflows to inf, still clipped, never NaN
}

TEST(IqlLosses, TdLossSumsBothQsMeanSquaredErrors) {
  Mat<double> q(2, 2);
  q << 1, 2, 3, 0;
  const Mat<double> y = row({2, 1});
  Mat<double> dq(2, 2);
  EXPECT_DOUBLE_EQ(tdLoss<double>(q, y, dq), (1.0 + 1 + 1 + 1) / 2);
  Mat<double> expected(2, 2);
  expected << -1, 1, 1, -1;  // 2 (q - y) / B
  EXPECT_LT((dq - expected).cwiseAbs().maxCoeff(), 1e-15);
}

}  // namespace
}  // namespace masa::offline
