#include "common/model/squashed_gaussian.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include "common/core/check.hpp"

namespace masa::sac::squashed_gaussian {
namespace {
template <typename S>
S softplus(S x) {
  return x > S(0) ? x + std::log1p(std::exp(-x)) : std::log1p(std::exp(x));
}
}  // namespace

template <typename S>
void drawNoise(Rng& rng, MatRef<S> eps) {
  std::normal_distribution<S> normal(S(0), S(1));
  for (Eigen::Index b = 0; b < eps.cols(); ++b)
    for (Eigen::Index d = 0; d < eps.rows(); ++d) eps(d, b) = normal(rng);
}

template <typename S>
void sample(const ConstMatRef<S>& mean, const ConstMatRef<S>& log_std, const ConstMatRef<S>& eps, MatRef<S> actions,
            MatRef<S> log_prob) {
  MASA_CHECK(mean.rows() == log_std.rows() && mean.cols() == log_std.cols() && eps.rows() == mean.rows() &&
                 eps.cols() == mean.cols() && actions.rows() == mean.rows() && actions.cols() == mean.cols() &&
                 log_prob.rows() == 1 && log_prob.cols() == mean.cols(),
             "squashed Gaussian: shapes differ");
  const S half_log_2pi = S(0.5) * std::log(S(2) * std::numbers::pi_v<S>);
  const S log2 = std::log(S(2));
  for (Eigen::Index b = 0; b < mean.cols(); ++b) {
    S lp = S(0);
    for (Eigen::Index d = 0; d < mean.rows(); ++d) {
      const S e = eps(d, b);
      const S u = mean(d, b) + std::exp(log_std(d, b)) * e;
      actions(d, b) = std::tanh(u);
      lp += S(-0.5) * e * e - log_std(d, b) - half_log_2pi - S(2) * (log2 - u - softplus(S(-2) * u));
    }
    log_prob(0, b) = lp;
  }
}

template <typename S>
void sampleBackward(const ConstMatRef<S>& log_std, const ConstMatRef<S>& eps, const ConstMatRef<S>& actions,
                    const ConstMatRef<S>& dactions, const ConstMatRef<S>& dlog_prob, MatRef<S> dmean,
                    MatRef<S> dlog_std) {
  for (Eigen::Index b = 0; b < actions.cols(); ++b)
    for (Eigen::Index d = 0; d < actions.rows(); ++d) {
      const S a = actions(d, b);
      const S du = dactions(d, b) * (S(1) - a * a) + dlog_prob(0, b) * S(2) * a;
      dmean(d, b) = du;
      dlog_std(d, b) = du * std::exp(log_std(d, b)) * eps(d, b) - dlog_prob(0, b);
    }
}

template void drawNoise<float>(Rng&, MatRef<float>);
template void drawNoise<double>(Rng&, MatRef<double>);
template void sample<float>(const ConstMatRef<float>&, const ConstMatRef<float>&, const ConstMatRef<float>&,
                            MatRef<float>, MatRef<float>);
template void sample<double>(const ConstMatRef<double>&, const ConstMatRef<double>&, const ConstMatRef<double>&,
                             MatRef<double>, MatRef<double>);
template void sampleBackward<float>(const ConstMatRef<float>&, const ConstMatRef<float>&, const ConstMatRef<float>&,
                                    const ConstMatRef<float>&, const ConstMatRef<float>&, MatRef<float>, MatRef<float>);
template void sampleBackward<double>(const ConstMatRef<double>&, const ConstMatRef<double>&, const ConstMatRef<double>&,
                                     const ConstMatRef<double>&, const ConstMatRef<double>&, MatRef<double>,
                                     MatRef<double>);

}  // namespace masa::sac::squashed_gaussian
