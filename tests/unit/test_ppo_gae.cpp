// GAE with time-outs kept apart from terminations, against advantages derived by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "learner/ppo/gae.hpp"

namespace masa::ppo {
namespace {

constexpr int kT = 4, kE = 3;
constexpr double kGamma = 0.9, kLambda = 0.8;

// env 0 terminates at t = 1 and starts over; env 1 times out at t = 2 (final-obs value kFinal) and
// starts over; env 2 runs through the horizon end. All three bootstrap from V(bootstrap obs).
constexpr double kFinal = 2.5;

template <typename S>
struct Case {
  StepMat<S> rewards{kT, kE}, values{kT, kE}, truncation_values{kT, kE}, adv{kT, kE}, ret{kT, kE};
  FlagMat terminated = FlagMat::Zero(kT, kE), truncated = FlagMat::Zero(kT, kE);
  Vec<S> bootstrap{kE};

  Case() {
    const double r[kT][kE] = {{1.0, -0.5, 0.25}, {2.0, 0.75, -1.0}, {-0.3, 1.5, 0.5}, {0.6, -2.0, 1.25}};
    const double v[kT][kE] = {{0.4, 1.1, -0.2}, {0.9, -0.7, 0.3}, {1.3, 0.2, 0.8}, {-0.6, 0.5, 1.7}};
    for (int t = 0; t < kT; ++t)
      for (int e = 0; e < kE; ++e) {
        rewards(t, e) = static_cast<S>(r[t][e]);
        values(t, e) = static_cast<S>(v[t][e]);
      }
    truncation_values.setConstant(S(99));  // read only where truncated
    truncation_values(2, 1) = static_cast<S>(kFinal);
    bootstrap << S(0.35), S(-0.45), S(1.2);
    terminated(1, 0) = 1;
    truncated(2, 1) = 1;
  }
  void run(const GaeConfig& c) {
    computeGae<S>(c, rewards, terminated, truncated, values, truncation_values, bootstrap, adv, ret);
  }
};

// The advantages written out as sums of deltas within each episode.
Eigen::Matrix<double, kT, kE> handComputed(bool value_bootstrap) {
  const double g = kGamma, gl = kGamma * kLambda;
  Case<double> c;
  auto r = [&](int t, int e) { return c.rewards(t, e); };
  auto v = [&](int t, int e) { return c.values(t, e); };
  Eigen::Matrix<double, kT, kE> a;
  // env 0: episode {0, 1} ends by termination, episode {2, 3} is cut by the horizon.
  const double d00 = r(0, 0) + g * v(1, 0) - v(0, 0);
  const double d10 = r(1, 0) - v(1, 0);
  const double d20 = r(2, 0) + g * v(3, 0) - v(2, 0);
  const double d30 = r(3, 0) + g * 0.35 - v(3, 0);
  a(0, 0) = d00 + gl * d10;
  a(1, 0) = d10;
  a(2, 0) = d20 + gl * d30;
  a(3, 0) = d30;
  // env 1: episode {0, 1, 2} ends by time-out, episode {3} is cut by the horizon.
  const double d01 = r(0, 1) + g * v(1, 1) - v(0, 1);
  const double d11 = r(1, 1) + g * v(2, 1) - v(1, 1);
  const double d21 = r(2, 1) + (value_bootstrap ? g * kFinal : 0.0) - v(2, 1);
  const double d31 = r(3, 1) + g * -0.45 - v(3, 1);
  a(0, 1) = d01 + gl * d11 + gl * gl * d21;
  a(1, 1) = d11 + gl * d21;
  a(2, 1) = d21;
  a(3, 1) = d31;
  // env 2: one episode over the whole horizon.
  double d[kT];
  for (int t = 0; t < kT; ++t) d[t] = r(t, 2) + g * (t + 1 < kT ? v(t + 1, 2) : 1.2) - v(t, 2);
  for (int t = 0; t < kT; ++t) {
    a(t, 2) = 0;
    for (int k = t; k < kT; ++k) a(t, 2) += std::pow(gl, k - t) * d[k];
  }
  return a;
}

template <typename S>
void expectHandComputed(double tol) {
  Case<S> c;
  c.run({kGamma, kLambda, true});
  const auto expected = handComputed(true);
  for (int t = 0; t < kT; ++t)
    for (int e = 0; e < kE; ++e) {
      EXPECT_NEAR(c.adv(t, e), expected(t, e), tol) << "t " << t << " e " << e;
      EXPECT_NEAR(c.ret(t, e), expected(t, e) + static_cast<double>(c.values(t, e)), tol) << "t " << t << " e " << e;
    }
}

TEST(GaeAdvantages, MatchHandComputedCaseInDouble) { expectHandComputed<double>(1e-12); }

TEST(GaeAdvantages, MatchHandComputedCaseInFloat) { expectHandComputed<float>(1e-6); }

TEST(GaeAdvantages, TimeOutBootstrapsFinalObsValueWhereTerminationDoesNot) {
  Case<double> timeout, termination;
  termination.truncated(2, 1) = 0;
  termination.terminated(2, 1) = 1;
  timeout.run({kGamma, kLambda, true});
  termination.run({kGamma, kLambda, true});
  EXPECT_NEAR(timeout.adv(2, 1) - termination.adv(2, 1), kGamma * kFinal, 1e-12);
  EXPECT_NEAR(timeout.adv(0, 1) - termination.adv(0, 1), std::pow(kGamma * kLambda, 2) * kGamma * kFinal, 1e-12);
  // Neither lets the next episode's values leak back.
  EXPECT_NEAR(timeout.adv(3, 1), termination.adv(3, 1), 1e-12);
}

TEST(GaeAdvantages, WithoutValueBootstrapTimeOutDropsFinalValueButStillEndsTheEpisode) {
  Case<double> c;
  c.run({kGamma, kLambda, false});
  const auto expected = handComputed(false);
  for (int t = 0; t < kT; ++t)
    for (int e = 0; e < kE; ++e) EXPECT_NEAR(c.adv(t, e), expected(t, e), 1e-12) << "t " << t << " e " << e;
  EXPECT_NEAR(c.adv(2, 1), c.rewards(2, 1) - c.values(2, 1), 1e-12);
}

TEST(GaeAdvantages, NextEpisodeValueDoesNotLeakThroughATimeOut) {
  Case<double> a, b;
  b.values(3, 1) += 10.0;  // first value of env 1's next episode
  a.run({kGamma, kLambda, true});
  b.run({kGamma, kLambda, true});
  for (int t = 0; t < 3; ++t) EXPECT_DOUBLE_EQ(a.adv(t, 1), b.adv(t, 1)) << "t " << t;
}

TEST(GaeAdvantages, StepBothTerminatedAndTruncatedCountsAsTerminated) {
  Case<double> both, termination;
  both.terminated(2, 1) = 1;
  termination.truncated(2, 1) = 0;
  termination.terminated(2, 1) = 1;
  both.run({kGamma, kLambda, true});
  termination.run({kGamma, kLambda, true});
  for (int t = 0; t < kT; ++t) EXPECT_DOUBLE_EQ(both.adv(t, 1), termination.adv(t, 1)) << "t " << t;
}

TEST(GaeAdvantages, DoneOnLastStepIgnoresBootstrapValue) {
  Case<double> a, b;
  a.terminated(3, 2) = 1;
  b.terminated(3, 2) = 1;
  b.bootstrap(2) += 100.0;
  a.run({kGamma, kLambda, true});
  b.run({kGamma, kLambda, true});
  EXPECT_DOUBLE_EQ(a.adv(3, 2), a.rewards(3, 2) - a.values(3, 2));
  for (int t = 0; t < kT; ++t) EXPECT_DOUBLE_EQ(a.adv(t, 2), b.adv(t, 2));
}

}  // namespace
}  // namespace masa::ppo
