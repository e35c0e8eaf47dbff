#include "common/model/diag_gaussian.hpp"

#include <cmath>

#include "common/core/check.hpp"

namespace masa::model::gaussian {
namespace {
constexpr double kLogSqrt2Pi = 0.91893853320467274178;  // log(sqrt(2 pi))

template <typename S>
void checkShapes(const ConstMatRef<S>& mean, const ConstVecRef<S>& log_std, const ConstMatRef<S>& action) {
  MASA_CHECK(mean.rows() == log_std.size(), "mean has " << mean.rows() << " rows, log_std " << log_std.size());
  MASA_CHECK(action.rows() == mean.rows() && action.cols() == mean.cols(),
             "action is " << action.rows() << "x" << action.cols() << ", mean " << mean.rows() << "x" << mean.cols());
}
}  // namespace

// Explicit loops: these run every minibatch, and Eigen expressions with per-call temporaries
// would allocate.
template <typename S>
void logProb(const ConstMatRef<S>& mean, const ConstVecRef<S>& log_std, const ConstMatRef<S>& action, MatRef<S> out) {
  checkShapes<S>(mean, log_std, action);
  MASA_CHECK(out.rows() == 1 && out.cols() == mean.cols(), "logProb output must be 1 x batch");
  const Eigen::Index a = mean.rows();
  const S norm = -log_std.sum() - S(kLogSqrt2Pi) * S(a);
  for (Eigen::Index b = 0; b < mean.cols(); ++b) {
    S acc = S(0);
    for (Eigen::Index d = 0; d < a; ++d) {
      const S z = (action(d, b) - mean(d, b)) * std::exp(-log_std(d));
      acc += z * z;
    }
    out(0, b) = S(-0.5) * acc + norm;
  }
}

template <typename S>
void logProbBackward(const ConstMatRef<S>& mean, const ConstVecRef<S>& log_std, const ConstMatRef<S>& action,
                     const ConstMatRef<S>& dlogp, MatRef<S> dmean, VecRef<S> dlog_std) {
  checkShapes<S>(mean, log_std, action);
  MASA_CHECK(dlogp.rows() == 1 && dlogp.cols() == mean.cols(), "dlogp must be 1 x batch");
  MASA_CHECK(dmean.rows() == mean.rows() && dmean.cols() == mean.cols(), "dmean has the wrong shape");
  MASA_CHECK(dlog_std.size() == log_std.size(), "dlog_std has the wrong size");
  const Eigen::Index a = mean.rows();
  for (Eigen::Index d = 0; d < a; ++d) {
    const S inv_var = std::exp(S(-2) * log_std(d));
    S dls = S(0);
    for (Eigen::Index b = 0; b < mean.cols(); ++b) {
      const S diff = action(d, b) - mean(d, b);
      const S g = dlogp(0, b);
      dmean(d, b) = g * diff * inv_var;
      dls += g * (diff * diff * inv_var - S(1));
    }
    dlog_std(d) += dls;
  }
}

template <typename S>
S entropy(const ConstVecRef<S>& log_std) {
  return log_std.sum() + S(log_std.size()) * S(0.5 + kLogSqrt2Pi);
}

template <typename S>
void sample(const ConstMatRef<S>& mean, const ConstVecRef<S>& log_std, Rng& rng, MatRef<S> out) {
  MASA_CHECK(mean.rows() == log_std.size() && out.rows() == mean.rows() && out.cols() == mean.cols(),
             "sample: shapes differ");
  std::normal_distribution<double> normal(0.0, 1.0);
  for (Eigen::Index b = 0; b < mean.cols(); ++b)
    for (Eigen::Index d = 0; d < mean.rows(); ++d)
      out(d, b) = mean(d, b) + std::exp(log_std(d)) * static_cast<S>(normal(rng));
}

template <typename S>
void kl(const ConstMatRef<S>& mean_old, const ConstMatRef<S>& log_std_old, const ConstMatRef<S>& mean_new,
        const ConstVecRef<S>& log_std_new, MatRef<S> out) {
  const Eigen::Index a = mean_old.rows(), B = mean_old.cols();
  MASA_CHECK(mean_new.rows() == a && mean_new.cols() == B,
             "mean_new is " << mean_new.rows() << "x" << mean_new.cols() << ", mean_old " << a << "x" << B);
  MASA_CHECK(log_std_new.size() == a, "log_std_new has " << log_std_new.size() << " entries, mean " << a << " rows");
  MASA_CHECK(log_std_old.rows() == a && (log_std_old.cols() == 1 || log_std_old.cols() == B),
             "log_std_old must be " << a << " x 1 or " << a << " x " << B << ", got " << log_std_old.rows() << "x"
                                    << log_std_old.cols());
  MASA_CHECK(out.rows() == 1 && out.cols() == B, "kl output must be 1 x batch");
  // KL = sum_d log(s_new/s_old) + (s_old^2 + (mu_old - mu_new)^2) / (2 s_new^2) - 1/2
  const bool shared = log_std_old.cols() == 1;
  S shared_constant = S(0);
  if (shared)
    for (Eigen::Index d = 0; d < a; ++d)
      shared_constant += log_std_new(d) - log_std_old(d, 0) +
                         S(0.5) * std::exp(S(2) * (log_std_old(d, 0) - log_std_new(d))) - S(0.5);
  for (Eigen::Index b = 0; b < B; ++b) {
    S acc = S(0), constant = shared_constant;
    for (Eigen::Index d = 0; d < a; ++d) {
      const S diff = mean_old(d, b) - mean_new(d, b);
      acc += diff * diff * std::exp(S(-2) * log_std_new(d));
      if (!shared)
        constant += log_std_new(d) - log_std_old(d, b) +
                    S(0.5) * std::exp(S(2) * (log_std_old(d, b) - log_std_new(d))) - S(0.5);
    }
    out(0, b) = S(0.5) * acc + constant;
  }
}

#define MASA_INSTANTIATE(S)                                                                                      \
  template void logProb<S>(const ConstMatRef<S>&, const ConstVecRef<S>&, const ConstMatRef<S>&, MatRef<S>);     \
  template void logProbBackward<S>(const ConstMatRef<S>&, const ConstVecRef<S>&, const ConstMatRef<S>&,         \
                                   const ConstMatRef<S>&, MatRef<S>, VecRef<S>);                                 \
  template S entropy<S>(const ConstVecRef<S>&);                                                                 \
  template void sample<S>(const ConstMatRef<S>&, const ConstVecRef<S>&, Rng&, MatRef<S>);                        \
  template void kl<S>(const ConstMatRef<S>&, const ConstMatRef<S>&, const ConstMatRef<S>&, const ConstVecRef<S>&, \
                      MatRef<S>);
MASA_INSTANTIATE(float)
MASA_INSTANTIATE(double)
#undef MASA_INSTANTIATE

}  // namespace masa::model::gaussian
