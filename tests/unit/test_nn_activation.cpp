#include <gtest/gtest.h>

#include <cmath>

#include "common/nn/activation.hpp"

namespace masa::nn {
namespace {

Mat<double> randomPreActivations(Rng& rng, int rows, int cols) {
  // Keeps |z| >= 1e-2 so that no finite-difference step crosses the kink of relu.
  std::uniform_real_distribution<double> mag(1e-2, 2.5);
  std::bernoulli_distribution neg(0.5);
  Mat<double> z(rows, cols);
  for (int c = 0; c < cols; ++c)
    for (int r = 0; r < rows; ++r) z(r, c) = neg(rng) ? -mag(rng) : mag(rng);
  return z;
}

class ActivationBackward : public ::testing::TestWithParam<Activation> {};

TEST_P(ActivationBackward, MatchesCentralFiniteDifferences) {
  const Activation a = GetParam();
  Rng rng(7);
  const Mat<double> z = randomPreActivations(rng, 9, 6);
  Mat<double> y(9, 6), dy = Mat<double>::Random(9, 6), dz(9, 6);
  activate<double>(a, z, y);
  activateBackward<double>(a, z, y, dy, dz);
  const double h = 1e-6;
  for (int c = 0; c < z.cols(); ++c)
    for (int r = 0; r < z.rows(); ++r) {
      Mat<double> zp = z.col(c).row(r), zm = zp, yp(1, 1), ym(1, 1);
      zp(0, 0) += h;
      zm(0, 0) -= h;
      activate<double>(a, zp, yp);
      activate<double>(a, zm, ym);
      const double fd = dy(r, c) * (yp(0, 0) - ym(0, 0)) / (2 * h);
      const double err = std::abs(fd - dz(r, c)) / std::max({std::abs(fd), std::abs(dz(r, c)), 1e-6});
      EXPECT_LT(err, 1e-6) << activationName(a) << " at z=" << z(r, c);
    }
}

TEST_P(ActivationBackward, InPlaceGivesTheSameResultAsSeparateBuffers) {
  const Activation a = GetParam();
  Rng rng(3);
  const Mat<float> z = randomPreActivations(rng, 33, 5).cast<float>();
  const Mat<float> dy = Mat<float>::Random(33, 5);
  Mat<float> y(33, 5), dz(33, 5);
  activate<float>(a, z, y);
  activateBackward<float>(a, z, y, dy, dz);
  Mat<float> inplace = z;
  activate<float>(a, inplace, inplace);
  EXPECT_EQ(inplace, y);
  Mat<float> dinplace = dy;
  activateBackward<float>(a, z, y, dinplace, dinplace);
  EXPECT_EQ(dinplace, dz);
}

INSTANTIATE_TEST_SUITE_P(AllActivations, ActivationBackward,
                         ::testing::Values(Activation::kIdentity, Activation::kElu, Activation::kTanh, Activation::kRelu),
                         [](const auto& info) { return activationName(info.param); });

TEST(ActivationForward, EluIsIdentityForPositiveAndExpMinusOneOtherwise) {
  Mat<float> z(1, 6);
  z << -20.f, -1.f, -1e-3f, 0.f, 1e-7f, 3.5f;
  Mat<float> y(1, 6);
  activate<float>(Activation::kElu, z, y);
  for (int i = 0; i < 6; ++i) {
    if (z(0, i) > 0)
      EXPECT_EQ(y(0, i), z(0, i));  // exactly: no (z + 1) - 1 rounding
    else
      EXPECT_NEAR(y(0, i), std::expm1(z(0, i)), 1e-6f);
  }
}

TEST(ActivationForward, ReluAndTanhMatchTheirDefinitions) {
  const Mat<double> z = Mat<double>::Random(4, 3) * 3.0;
  Mat<double> y(4, 3);
  activate<double>(Activation::kRelu, z, y);
  EXPECT_EQ(y, z.cwiseMax(0.0));
  activate<double>(Activation::kTanh, z, y);
  for (int i = 0; i < z.size(); ++i) EXPECT_NEAR(y(i), std::tanh(z(i)), 1e-15);
}

TEST(ActivationNames, RoundTripAndUnknownNameThrows) {
  for (Activation a : {Activation::kIdentity, Activation::kElu, Activation::kTanh, Activation::kRelu})
    EXPECT_EQ(parseActivation(activationName(a)), a);
  EXPECT_THROW(parseActivation("gelu"), std::invalid_argument);
}

}  // namespace
}  // namespace masa::nn
