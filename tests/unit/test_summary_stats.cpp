// The comparison's statistics against cases computed by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "common/core/summary_stats.hpp"

using namespace masa::stats;

TEST(SummaryStats, QuantileInterpolatesBetweenOrderStatisticsLikeNumpy) {
  // numpy.quantile([4, 1, 3, 2], [0, .25, .5, .75, 1]) = [1, 1.75, 2.5, 3.25, 4]
  const std::vector<double> v = {4, 1, 3, 2};
  EXPECT_DOUBLE_EQ(quantile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(quantile(v, 0.25), 1.75);
  EXPECT_DOUBLE_EQ(quantile(v, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(quantile(v, 0.75), 3.25);
  EXPECT_DOUBLE_EQ(quantile(v, 1.0), 4.0);
  EXPECT_DOUBLE_EQ(median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(median({7}), 7.0);
  // Five seeds: [10, 20, 30, 40, 50] -> quartiles 20 and 40.
  EXPECT_DOUBLE_EQ(quantile({50, 10, 40, 20, 30}, 0.25), 20.0);
  EXPECT_DOUBLE_EQ(quantile({50, 10, 40, 20, 30}, 0.75), 40.0);
  EXPECT_TRUE(std::isnan(median({})));
  EXPECT_THROW(quantile(v, 1.5), std::invalid_argument);
}

TEST(SummaryStats, MeanUnderCurveIsTheTrapezoidAreaOverTheRange) {
  // (0,0)-(1,2)-(3,2): area 1 + 4 = 5 over a range of 3.
  EXPECT_DOUBLE_EQ(meanUnderCurve({0, 1, 3}, {0, 2, 2}, 1e9), 5.0 / 3.0);
  // x_max cuts the last point: only (0,0)-(1,2), area 1 over 1.
  EXPECT_DOUBLE_EQ(meanUnderCurve({0, 1, 3}, {0, 2, 2}, 2.0), 1.0);
  // A NaN point is skipped: (0,0)-(2,4), area 4 over 2.
  EXPECT_DOUBLE_EQ(meanUnderCurve({0, 1, 2}, {0, NAN, 4}, 1e9), 2.0);
  EXPECT_TRUE(std::isnan(meanUnderCurve({0}, {1}, 1e9)));
}

TEST(SummaryStats, FirstCrossingInterpolatesToTheLevel) {
  EXPECT_DOUBLE_EQ(firstCrossing({0, 10, 20}, {0, 5, 10}, 7.5), 15.0);
  EXPECT_DOUBLE_EQ(firstCrossing({0, 10, 20}, {0, 5, 10}, 5.0), 10.0);
  // The first crossing, not a later one: up to 6 at x = 10, down, up again.
  EXPECT_DOUBLE_EQ(firstCrossing({0, 10, 20, 30}, {0, 6, 1, 9}, 3.0), 5.0);
  EXPECT_DOUBLE_EQ(firstCrossing({5, 10}, {4, 1}, 2.0), 5.0);  // already there at the start
  EXPECT_TRUE(std::isnan(firstCrossing({0, 10}, {0, 1}, 2.0)));
}

TEST(SummaryStats, FirstReachedIsTheFirstMeasurementAtTheLevel) {
  // Evaluations at 0, 10, 20, 30 (NaN: no evaluation at that update): no interpolation.
  EXPECT_DOUBLE_EQ(firstReached({0, 5, 10, 20, 30}, {1, NAN, 4, 6, 9}, 5.0, 1e9), 20.0);
  EXPECT_DOUBLE_EQ(firstReached({0, 10, 20}, {1, 5, 9}, 5.0, 1e9), 10.0);  // reaching is enough
  EXPECT_DOUBLE_EQ(firstReached({0, 10, 20, 30}, {0, 6, 1, 9}, 5.0, 1e9), 10.0);  // the first time
  EXPECT_DOUBLE_EQ(firstReached({5, 10}, {7, 1}, 5.0, 1e9), 5.0);
  // Beyond x_max does not count: the budget every run of a comparison shares.
  EXPECT_TRUE(std::isnan(firstReached({0, 10, 20}, {1, 2, 9}, 5.0, 15.0)));
  EXPECT_TRUE(std::isnan(firstReached({0, 10}, {NAN, 4}, 5.0, 1e9)));
  EXPECT_THROW(firstReached({0, 1}, {0}, 1.0, 1e9), std::invalid_argument);
}

TEST(SummaryStats, FirstFallenToIsTheFirstMeasurementAtOrBelowTheLevel) {
  // An error measured at 0, 10, 20, 30: the first time it is at most the level, not interpolated.
  EXPECT_DOUBLE_EQ(firstFallenTo({0, 5, 10, 20, 30}, {9, NAN, 6, 4, 1}, 5.0, 1e9), 20.0);
  EXPECT_DOUBLE_EQ(firstFallenTo({0, 10, 20}, {9, 5, 1}, 5.0, 1e9), 10.0);  // reaching is enough
  EXPECT_DOUBLE_EQ(firstFallenTo({0, 10, 20, 30}, {9, 4, 8, 1}, 5.0, 1e9), 10.0);  // the first time
  EXPECT_DOUBLE_EQ(firstFallenTo({5, 10}, {1, 7}, 5.0, 1e9), 5.0);
  // A rising figure above the level has not fallen to it (firstReached would say 10).
  EXPECT_TRUE(std::isnan(firstFallenTo({0, 10, 20}, {6, 7, 9}, 5.0, 1e9)));
  EXPECT_TRUE(std::isnan(firstFallenTo({0, 10, 20}, {9, 8, 1}, 5.0, 15.0)));  // beyond x_max
  EXPECT_THROW(firstFallenTo({0, 1}, {0}, 1.0, 1e9), std::invalid_argument);
}

TEST(SummaryStats, TrailingMeanAveragesThePastWindow) {
  const auto m = trailingMean({1, 2, 3, 4, NAN, 6}, 3);
  ASSERT_EQ(m.size(), 6u);
  EXPECT_DOUBLE_EQ(m[0], 1.0);
  EXPECT_DOUBLE_EQ(m[1], 1.5);
  EXPECT_DOUBLE_EQ(m[2], 2.0);
  EXPECT_DOUBLE_EQ(m[3], 3.0);
  EXPECT_DOUBLE_EQ(m[4], 3.5);  // (3 + 4) / 2: the NaN is left out
  EXPECT_DOUBLE_EQ(m[5], 5.0);  // (4 + 6) / 2
}

TEST(SummaryStats, BootstrapOfConstantGroupsIsExact) {
  masa::Rng rng(1);
  const auto iv = bootstrapMeanDifference({3, 3, 3}, {1, 1}, 1000, 0.95, rng);
  EXPECT_DOUBLE_EQ(iv.estimate, 2.0);
  EXPECT_DOUBLE_EQ(iv.low, 2.0);
  EXPECT_DOUBLE_EQ(iv.high, 2.0);
}

TEST(SummaryStats, BootstrapIntervalMatchesTheHandComputedResamplingDistribution) {
  // a = {0, 2}, b = {0}: a's resampled mean is 0 (p 1/4), 1 (p 1/2) or 2 (p 1/4), so the 2.5% and
  // 97.5% quantiles of the difference are 0 and 2, and about half the resamples give 1.
  masa::Rng rng(7);
  const auto iv = bootstrapMeanDifference({0, 2}, {0}, 20000, 0.95, rng);
  EXPECT_DOUBLE_EQ(iv.estimate, 1.0);
  EXPECT_DOUBLE_EQ(iv.low, 0.0);
  EXPECT_DOUBLE_EQ(iv.high, 2.0);
  // A 40% interval lies inside the central mass: both ends at 1.
  const auto narrow = bootstrapMeanDifference({0, 2}, {0}, 20000, 0.4, rng);
  EXPECT_DOUBLE_EQ(narrow.low, 1.0);
  EXPECT_DOUBLE_EQ(narrow.high, 1.0);
}

TEST(SummaryStats, BootstrapIsReproducibleFromItsSeedAndSeparatesDistinctGroups) {
  const std::vector<double> a = {10, 12, 11, 13, 9}, b = {1, 3, 2, 0, 4};
  masa::Rng r1(42), r2(42);
  const auto i1 = bootstrapMeanDifference(a, b, 2000, 0.95, r1);
  const auto i2 = bootstrapMeanDifference(a, b, 2000, 0.95, r2);
  EXPECT_EQ(i1.low, i2.low);
  EXPECT_EQ(i1.high, i2.high);
  EXPECT_DOUBLE_EQ(i1.estimate, 9.0);
  EXPECT_GT(i1.low, 6.0);  // the groups' spreads are 1.4: far from overlapping
  EXPECT_LT(i1.high, 12.0);
  EXPECT_LT(i1.low, i1.estimate);
  EXPECT_GT(i1.high, i1.estimate);
  EXPECT_THROW(bootstrapMeanDifference({}, b, 10, 0.95, r1), std::invalid_argument);
}
