#include <gtest/gtest.h>

#include <initializer_list>
#include <sstream>
#include <stdexcept>

#include "common/nn/optimized_net.hpp"

namespace masa::nn {
namespace {

// A one-segment set holding `values`.
ParameterSet<double> setOf(std::initializer_list<double> values) {
  ParameterSet<double> p;
  p.reserve("x", static_cast<int>(values.size()));
  p.finalize();
  int i = 0;
  for (double v : values) p.values()(i++) = v;
  return p;
}

// The trainers' state files keep their byte layout only if the net's step is a plain Adam's at
// the given rate (defaults otherwise) and its saved state is that Adam's.
TEST(OptimizedNet, StepsAsABareAdamAtTheGivenRateAndSavesItsState) {
  ParameterSet<double> a = setOf({1.0, -2.0, 0.5}), b = setOf({1.0, -2.0, 0.5});
  AdamConfig<double> config;
  config.lr = 0.05;
  Adam<double> bare(b, config);
  OptimizedNet<double> net(a, 0.05);
  const Vec<double> g = (Vec<double>(3) << 0.3, -4.0, 0.25).finished();
  for (int t = 0; t < 3; ++t) {
    a.grads() = g;
    b.grads() = g;
    net.step();
    bare.step();
  }
  for (int i = 0; i < 3; ++i) EXPECT_EQ(a.values()(i), b.values()(i)) << i;
  EXPECT_NE(a.values()(0), 1.0);
  std::ostringstream from_net, from_bare;
  net.saveOptimizer(from_net);
  bare.save(from_bare);
  EXPECT_EQ(from_net.str(), from_bare.str());

  // A schedule's rate applies from the next step on.
  net.setLearningRate(0.0);
  const Vec<double> before = a.values();
  a.grads() = g;
  net.step();
  EXPECT_EQ(a.values(), before);
  EXPECT_EQ(net.adam().stepCount(), 4);
}

TEST(OptimizedNet, ARangeNetStepsOnlyItsValues) {
  ParameterSet<double> p = setOf({1.0, 2.0, 3.0, 4.0});
  OptimizedNet<double> middle(p, 0.1, 1, 3);
  p.grads().setConstant(1.0);
  middle.step();
  EXPECT_EQ(p.values()(0), 1.0);
  EXPECT_NE(p.values()(1), 2.0);
  EXPECT_NE(p.values()(2), 3.0);
  EXPECT_EQ(p.values()(3), 4.0);
  EXPECT_THROW(middle.copyToTarget(), std::exception) << "a range net has no target";
}

TEST(OptimizedNet, TheTargetStartsAsAnExactCopyAndFollowsByPolyak) {
  ParameterSet<double> online = setOf({0.1, -0.7, 1e-3}), target = setOf({5.0, 5.0, 5.0});
  OptimizedNet<double> net(online, 0.1, &target);
  net.copyToTarget();
  EXPECT_EQ(target.values(), online.values());

  online.values() << 1.0, -1.0, 2.0;
  const Vec<double> old = target.values();
  net.updateTarget(0.25);
  for (int i = 0; i < 3; ++i)
    EXPECT_DOUBLE_EQ(target.values()(i), old(i) + 0.25 * (online.values()(i) - old(i))) << i;
  EXPECT_NE(target.values(), online.values());
}

TEST(OptimizedNet, ATargetOfAnotherSizeIsRefused) {
  ParameterSet<double> online = setOf({1.0, 2.0, 3.0}), other = setOf({1.0, 2.0});
  EXPECT_THROW(OptimizedNet<double>(online, 0.1, &other), std::exception);
  EXPECT_THROW(polyakUpdate(online, other, 0.5), std::exception);
}

}  // namespace
}  // namespace masa::nn
