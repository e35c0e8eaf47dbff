#include <gtest/gtest.h>

#include <stdexcept>

#include "common/nn/parameter_set.hpp"

namespace masa::nn {
namespace {

TEST(ParameterSet, ReservesConsecutiveSegmentsInOrder) {
  ParameterSet<double> p;
  EXPECT_EQ(p.reserve("a", 3, 2), 0);
  EXPECT_EQ(p.reserve("b", 4), 6);
  EXPECT_EQ(p.reserve("c", 1, 5), 10);
  EXPECT_EQ(p.size(), 15);
  ASSERT_EQ(p.segments().size(), 3u);
  EXPECT_EQ(p.segment("b").offset, 6);
  EXPECT_EQ(p.segment("b").rows, 4);
  EXPECT_EQ(p.segment("b").cols, 1);
  EXPECT_EQ(p.segment("c").size(), 5);
}

TEST(ParameterSet, FinalizeZeroInitialisesValuesAndGradsAndIsIdempotent) {
  ParameterSet<float> p;
  p.reserve("w", 3, 3);
  p.finalize();
  ASSERT_EQ(p.values().size(), 9);
  ASSERT_EQ(p.grads().size(), 9);
  EXPECT_TRUE((p.values().array() == 0.f).all());
  EXPECT_TRUE((p.grads().array() == 0.f).all());
  p.values()(4) = 2.f;
  p.finalize();
  EXPECT_EQ(p.values()(4), 2.f);
}

TEST(ParameterSet, RejectsReserveAfterFinalize) {
  ParameterSet<double> p;
  p.reserve("a", 2);
  p.finalize();
  EXPECT_THROW(p.reserve("b", 2), std::invalid_argument);
}

TEST(ParameterSet, RejectsDuplicateNames) {
  ParameterSet<double> p;
  p.reserve("a", 2);
  EXPECT_THROW(p.reserve("a", 3), std::invalid_argument);
}

TEST(ParameterSet, RejectsUnknownSegmentName) {
  ParameterSet<double> p;
  p.reserve("a", 2);
  EXPECT_THROW(p.segment("nope"), std::invalid_argument);
}

TEST(ParameterSet, ViewsAreColumnMajorWindowsOfTheFlatVectors) {
  ParameterSet<double> p;
  p.reserve("a", 2);
  const int off = p.reserve("w", 2, 3);
  p.finalize();
  p.values().setLinSpaced(p.size(), 0.0, p.size() - 1.0);
  auto w = p.value(off, 2, 3);
  EXPECT_EQ(w(0, 0), 2.0);
  EXPECT_EQ(w(1, 0), 3.0);
  EXPECT_EQ(w(0, 1), 4.0);
  w(1, 2) = -1.0;
  EXPECT_EQ(p.values()(7), -1.0);
  p.grad(off, 2, 3)(0, 2) = 5.0;
  EXPECT_EQ(p.grads()(6), 5.0);
  p.zeroGrad();
  EXPECT_EQ(p.grads()(6), 0.0);
}

TEST(ParameterSet, ViewsRequireFinalizeAndStayInBounds) {
  ParameterSet<double> p;
  p.reserve("a", 4);
  EXPECT_THROW(p.value(0, 4, 1), std::invalid_argument);
  p.finalize();
  EXPECT_THROW(p.value(2, 3, 1), std::invalid_argument);
  EXPECT_THROW(p.grad(-1, 1, 1), std::invalid_argument);
}

}  // namespace
}  // namespace masa::nn
