#include "common/core/summary_stats.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace masa::stats {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

double quantile(std::vector<double> values, double q) {
  if (!(q >= 0.0 && q <= 1.0)) throw std::invalid_argument("quantile: q must be in [0, 1]");
  if (values.empty()) return kNaN;
  std::sort(values.begin(), values.end());
  const double h = (static_cast<double>(values.size()) - 1.0) * q;
  const auto lo = static_cast<size_t>(std::floor(h));
  const size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (h - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

double median(std::vector<double> values) { return quantile(std::move(values), 0.5); }

double mean(const std::vector<double>& values) {
  if (values.empty()) return kNaN;
  double sum = 0;
  for (double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

double meanUnderCurve(const std::vector<double>& x, const std::vector<double>& y, double x_max) {
  if (x.size() != y.size()) throw std::invalid_argument("meanUnderCurve: x and y differ in length");
  double area = 0, x_first = kNaN, x_prev = kNaN, y_prev = kNaN;
  for (size_t i = 0; i < x.size(); ++i) {
    if (x[i] > x_max) break;
    if (std::isnan(y[i])) continue;
    if (std::isnan(x_first)) {
      x_first = x[i];
    } else {
      if (x[i] < x_prev) throw std::invalid_argument("meanUnderCurve: x must increase");
      area += 0.5 * (y[i] + y_prev) * (x[i] - x_prev);
    }
    x_prev = x[i];
    y_prev = y[i];
  }
  if (std::isnan(x_first) || x_prev <= x_first) return kNaN;
  return area / (x_prev - x_first);
}

double firstCrossing(const std::vector<double>& x, const std::vector<double>& y, double level) {
  if (x.size() != y.size()) throw std::invalid_argument("firstCrossing: x and y differ in length");
  double x_prev = kNaN, y_prev = kNaN;
  for (size_t i = 0; i < x.size(); ++i) {
    if (std::isnan(y[i])) continue;
    if (y[i] >= level) {
      if (std::isnan(y_prev)) return x[i];
      return x_prev + (level - y_prev) / (y[i] - y_prev) * (x[i] - x_prev);
    }
    x_prev = x[i];
    y_prev = y[i];
  }
  return kNaN;
}

namespace {
// The x of the first point at x <= x_max whose y is at the level (`holds`); NaN values are skipped.
template <class Holds>
double firstWhere(const char* name, const std::vector<double>& x, const std::vector<double>& y, double x_max,
                  Holds holds) {
  if (x.size() != y.size()) throw std::invalid_argument(std::string(name) + ": x and y differ in length");
  for (size_t i = 0; i < x.size() && x[i] <= x_max; ++i)
    if (!std::isnan(y[i]) && holds(y[i])) return x[i];
  return kNaN;
}
}  // namespace

double firstReached(const std::vector<double>& x, const std::vector<double>& y, double level, double x_max) {
  return firstWhere("firstReached", x, y, x_max, [level](double v) { return v >= level; });
}

double firstFallenTo(const std::vector<double>& x, const std::vector<double>& y, double level, double x_max) {
  return firstWhere("firstFallenTo", x, y, x_max, [level](double v) { return v <= level; });
}

std::vector<double> trailingMean(const std::vector<double>& y, int window) {
  if (window < 1) throw std::invalid_argument("trailingMean: window must be at least 1");
  std::vector<double> out(y.size(), kNaN);
  for (size_t i = 0; i < y.size(); ++i) {
    double sum = 0;
    int n = 0;
    for (size_t j = i + 1 > static_cast<size_t>(window) ? i + 1 - window : 0; j <= i; ++j)
      if (!std::isnan(y[j])) { sum += y[j]; ++n; }
    if (n > 0) out[i] = sum / n;
  }
  return out;
}

Interval bootstrapMeanDifference(const std::vector<double>& a, const std::vector<double>& b, int resamples,
                                 double level, Rng& rng) {
  if (a.empty() || b.empty()) throw std::invalid_argument("bootstrapMeanDifference: a group is empty");
  if (resamples < 1 || !(level > 0 && level < 1))
    throw std::invalid_argument("bootstrapMeanDifference: needs resamples >= 1 and 0 < level < 1");
  std::uniform_int_distribution<size_t> pick_a(0, a.size() - 1), pick_b(0, b.size() - 1);
  std::vector<double> diffs(resamples);
  for (int r = 0; r < resamples; ++r) {
    double sa = 0, sb = 0;
    for (size_t i = 0; i < a.size(); ++i) sa += a[pick_a(rng)];
    for (size_t i = 0; i < b.size(); ++i) sb += b[pick_b(rng)];
    diffs[r] = sa / static_cast<double>(a.size()) - sb / static_cast<double>(b.size());
  }
  Interval out;
  out.estimate = mean(a) - mean(b);
  out.low = quantile(diffs, 0.5 * (1.0 - level));
  out.high = quantile(std::move(diffs), 0.5 * (1.0 + level));
  return out;
}

}  // namespace masa::stats
