#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "common/nn/mlp.hpp"

namespace masa::nn {
namespace {

template <typename S>
struct Net {
  ParameterSet<S> params;
  std::unique_ptr<Mlp<S>> mlp;
  Net(const MlpShape& shape, std::uint64_t seed) {
    mlp = std::make_unique<Mlp<S>>(params, "net", shape);
    params.finalize();
    Rng rng(seed);
    mlp->initialize(rng);
  }
};

MlpShape shapeWith(int in, std::vector<int> hidden, int out, Activation hidden_act,
                   Activation out_act = Activation::kIdentity) {
  MlpShape s;
  s.input = in;
  s.hidden = std::move(hidden);
  s.output = out;
  s.hidden_activation = hidden_act;
  s.output_activation = out_act;
  return s;
}

double relErr(double a, double b) { return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-6}); }

// loss = sum(w .* mlp(x)); compares the analytic gradient of every parameter and every input with
// central differences.
void expectGradientsMatchFiniteDifferences(const MlpShape& shape) {
  Net<double> net(shape, 11);
  Rng rng(5);
  std::normal_distribution<double> n01;
  const int B = 5;
  Mat<double> x(shape.input, B), w(shape.output, B);
  for (int i = 0; i < x.size(); ++i) x(i) = n01(rng);
  for (int i = 0; i < w.size(); ++i) w(i) = n01(rng);
  auto loss = [&](const Mat<double>& in) { return (w.array() * net.mlp->forward(in).array()).sum(); };

  net.params.zeroGrad();
  net.mlp->forward(x);
  Mat<double> dx(shape.input, B);
  MatRef<double> dx_ref(dx);
  net.mlp->backward(w, &dx_ref);
  const Vec<double> grads = net.params.grads();

  const double h = 1e-6;
  double worst = 0;
  Vec<double>& v = net.params.values();
  for (int i = 0; i < v.size(); ++i) {
    const double orig = v(i);
    v(i) = orig + h;
    const double lp = loss(x);
    v(i) = orig - h;
    const double lm = loss(x);
    v(i) = orig;
    const double fd = (lp - lm) / (2 * h);
    worst = std::max(worst, relErr(fd, grads(i)));
    EXPECT_LT(relErr(fd, grads(i)), 1e-4) << "parameter " << i << ": analytic " << grads(i) << ", fd " << fd;
  }
  for (int i = 0; i < x.size(); ++i) {
    Mat<double> xp = x, xm = x;
    xp(i) += h;
    xm(i) -= h;
    const double fd = (loss(xp) - loss(xm)) / (2 * h);
    worst = std::max(worst, relErr(fd, dx(i)));
    EXPECT_LT(relErr(fd, dx(i)), 1e-4) << "input " << i << ": analytic " << dx(i) << ", fd " << fd;
  }
  char worst_text[32];
  std::snprintf(worst_text, sizeof(worst_text), "%.2e", worst);
  ::testing::Test::RecordProperty("worst_relative_error", worst_text);
}

TEST(MlpGradient, MatchesCentralFiniteDifferencesForElu) {
  expectGradientsMatchFiniteDifferences(shapeWith(4, {7, 6}, 3, Activation::kElu));
}

TEST(MlpGradient, MatchesCentralFiniteDifferencesForTanh) {
  expectGradientsMatchFiniteDifferences(shapeWith(4, {7, 6}, 3, Activation::kTanh, Activation::kTanh));
}

TEST(MlpGradient, MatchesCentralFiniteDifferencesWithoutHiddenLayers) {
  expectGradientsMatchFiniteDifferences(shapeWith(5, {}, 3, Activation::kElu));
}

TEST(MlpGradient, AccumulatesAcrossBackwardCalls) {
  const MlpShape shape = shapeWith(3, {8}, 2, Activation::kElu);
  Net<double> net(shape, 1);
  const Mat<double> x1 = Mat<double>::Random(3, 4), x2 = Mat<double>::Random(3, 6);
  const Mat<double> d1 = Mat<double>::Random(2, 4), d2 = Mat<double>::Random(2, 6);

  net.params.zeroGrad();
  net.mlp->forward(x1);
  net.mlp->backward(d1);
  const Vec<double> g1 = net.params.grads();
  net.params.zeroGrad();
  net.mlp->forward(x2);
  net.mlp->backward(d2);
  const Vec<double> g2 = net.params.grads();

  net.params.zeroGrad();
  net.mlp->forward(x1);
  net.mlp->backward(d1);
  net.mlp->forward(x2);
  net.mlp->backward(d2);
  ASSERT_GT(g1.norm(), 0.0);
  ASSERT_GT(g2.norm(), 0.0);
  EXPECT_LT((net.params.grads() - (g1 + g2)).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(MlpForward, BatchedEqualsPerSample) {
  const MlpShape shape = shapeWith(6, {32, 16}, 4, Activation::kElu, Activation::kTanh);
  Net<double> net(shape, 2);
  const Mat<double> x = Mat<double>::Random(6, 9);
  const Mat<double> batched = net.mlp->forward(x);
  for (int c = 0; c < x.cols(); ++c) {
    const Mat<double> single = net.mlp->forward(x.col(c));
    EXPECT_LT((single - batched.col(c)).cwiseAbs().maxCoeff(), 1e-13) << "column " << c;
  }
}

TEST(MlpForward, InferEqualsForwardAndBackwardAfterInferThrows) {
  const MlpShape shape = shapeWith(5, {12, 7}, 3, Activation::kElu);
  Net<float> net(shape, 4);
  const Mat<float> x = Mat<float>::Random(5, 10);
  const Mat<float> y = net.mlp->forward(x);
  const Mat<float> yi = net.mlp->infer(x);
  EXPECT_EQ(y, yi);
  EXPECT_THROW(net.mlp->backward(Mat<float>::Ones(3, 10)), std::invalid_argument);
}

TEST(MlpForward, GrowsBuffersForLargerBatchesAndChecksInputRows) {
  const MlpShape shape = shapeWith(3, {5}, 2, Activation::kRelu);
  Net<double> net(shape, 8);
  const Mat<double> small = Mat<double>::Random(3, 2), large = Mat<double>::Random(3, 50);
  const Mat<double> y_small = net.mlp->forward(small);
  const Mat<double> y_large = net.mlp->forward(large);
  EXPECT_EQ(y_large.cols(), 50);
  const Mat<double> y_small_again = net.mlp->forward(small);
  EXPECT_EQ(y_small_again, y_small);
  EXPECT_THROW(net.mlp->forward(Mat<double>::Zero(4, 2)), std::invalid_argument);
  net.mlp->forward(small);
  EXPECT_THROW(net.mlp->backward(Mat<double>::Zero(2, 3)), std::invalid_argument);
}

TEST(MlpForward, EmptyBatchGivesEmptyOutputAndNoGradient) {
  Net<float> net(shapeWith(3, {4}, 2, Activation::kElu), 6);
  const Mat<float> x(3, 0);
  EXPECT_EQ(net.mlp->forward(x).cols(), 0);
  net.mlp->backward(Mat<float>(2, 0));
  EXPECT_EQ(net.params.grads().squaredNorm(), 0.f);
}

TEST(MlpInitialize, FollowsPyTorchLinearBoundsScalesLastLayerAndIsReproducible) {
  const MlpShape shape = shapeWith(16, {64}, 4, Activation::kElu);
  ParameterSet<double> p1, p2;
  Mlp<double> a(p1, "pi", shape), b(p2, "pi", shape);
  p1.finalize();
  p2.finalize();
  Rng r1(42), r2(42);
  a.initialize(r1);
  b.initialize(r2, 0.01);
  EXPECT_EQ(a.numParams(), p1.size());
  EXPECT_EQ(a.numParams(), 16 * 64 + 64 + 64 * 4 + 4);
  const auto& w0 = p1.segment("pi.layer0.weight");
  const auto& b1 = p1.segment("pi.layer1.bias");
  const auto& w1 = p1.segment("pi.layer1.weight");
  EXPECT_EQ(w0.rows, 64);
  EXPECT_EQ(w0.cols, 16);
  const auto v0 = p1.values().segment(w0.offset, w0.size());
  EXPECT_LE(v0.cwiseAbs().maxCoeff(), 1.0 / 4.0);
  EXPECT_GT(v0.cwiseAbs().maxCoeff(), 0.9 / 4.0);  // spread over the whole range, not a tiny one
  EXPECT_LE(p1.values().segment(b1.offset, b1.size()).cwiseAbs().maxCoeff(), 1.0 / 8.0);
  // Same seed: identical except the last layer's weights, which are scaled.
  EXPECT_EQ(p1.values().head(w1.offset), p2.values().head(w1.offset));
  EXPECT_EQ((p1.values().segment(w1.offset, w1.size()) * 0.01).eval(), p2.values().segment(w1.offset, w1.size()));
  EXPECT_EQ(p1.values().segment(b1.offset, b1.size()), p2.values().segment(b1.offset, b1.size()));
}

}  // namespace
}  // namespace masa::nn
