// Statistics for comparing training curves over seeds: quantiles, the mean under a curve, the
// first crossing of a level, and a bootstrap interval for a difference of means. Used by
// masa_compare (the paper's figure and verdict); checked against hand-computed cases.
#pragma once

#include <vector>

#include "common/core/types.hpp"

namespace masa::stats {

// The q-quantile (0 <= q <= 1) with linear interpolation between order statistics (Hyndman & Fan
// type 7: R's and numpy's default). NaN for no values. Throws for q outside [0, 1].
double quantile(std::vector<double> values, double q);
double median(std::vector<double> values);
double mean(const std::vector<double>& values);

// The area under y(x) by the trapezoid rule over the points with x <= x_max, divided by the
// x range covered: the curve's mean height. Points must be in increasing x. NaN for fewer than two
// points; a NaN y is skipped (the neighbours are joined).
double meanUnderCurve(const std::vector<double>& x, const std::vector<double>& y, double x_max);

// The first x at which y reaches `level` (y >= level), linearly interpolated between the point
// below and the point at or above it; NaN when y never reaches it. The first point counts as
// reached at its own x.
double firstCrossing(const std::vector<double>& x, const std::vector<double>& y, double level);

// The x of the first point with y >= level, not interpolated: for a figure measured only now and
// then (an evaluation every N updates), where nothing is known between two measurements. NaN
// values are skipped; NaN when y never reaches the level at x <= x_max.
double firstReached(const std::vector<double>& x, const std::vector<double>& y, double level, double x_max);

// The same for a figure that should fall (an error): the x of the first point with y <= level.
double firstFallenTo(const std::vector<double>& x, const std::vector<double>& y, double level, double x_max);

// Trailing mean over `window` points (fewer at the start); NaN values are left out of the mean.
std::vector<double> trailingMean(const std::vector<double>& y, int window);

struct Interval {
  double estimate = 0;  // mean(a) - mean(b)
  double low = 0;
  double high = 0;
};

// mean(a) - mean(b) with a percentile bootstrap interval at `level` (e.g. 0.95): `resamples` times,
// a and b are each resampled with replacement (seeds are independent runs), and the interval is
// the (1-level)/2 and (1+level)/2 quantiles of the resampled differences. Throws for an empty a or b.
Interval bootstrapMeanDifference(const std::vector<double>& a, const std::vector<double>& b, int resamples,
                                 double level, Rng& rng);

}  // namespace masa::stats
