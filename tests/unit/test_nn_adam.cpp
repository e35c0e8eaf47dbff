#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/nn/adam.hpp"

namespace masa::nn {
namespace {

ParameterSet<double> makeParams(int n) {
  ParameterSet<double> p;
  p.reserve("x", n);
  p.finalize();
  return p;
}

TEST(Adam, TwoStepsMatchTheTextbookBiasCorrectedUpdate) {
  ParameterSet<double> p = makeParams(3);
  p.values() << 1.0, -2.0, 0.5;
  AdamConfig<double> cfg;
  cfg.lr = 0.1;
  cfg.beta1 = 0.8;
  cfg.beta2 = 0.9;
  cfg.eps = 1e-3;
  Adam<double> adam(p, cfg);
  const Vec<double> g1 = (Vec<double>(3) << 0.3, -4.0, 0.0).finished();
  const Vec<double> g2 = (Vec<double>(3) << -1.0, 2.0, 0.25).finished();

  Vec<double> x = p.values(), m = Vec<double>::Zero(3), v = Vec<double>::Zero(3);
  for (int t = 1; t <= 2; ++t) {
    const Vec<double>& g = t == 1 ? g1 : g2;
    p.grads() = g;
    adam.step();
    for (int i = 0; i < 3; ++i) {
      m(i) = 0.8 * m(i) + 0.2 * g(i);
      v(i) = 0.9 * v(i) + 0.1 * g(i) * g(i);
      const double mhat = m(i) / (1 - std::pow(0.8, t)), vhat = v(i) / (1 - std::pow(0.9, t));
      x(i) -= 0.1 * mhat / (std::sqrt(vhat) + 1e-3);
    }
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(p.values()(i), x(i), 1e-14) << "step " << t << " index " << i;
  }
  EXPECT_EQ(adam.stepCount(), 2);
}

// Two optimizers on two ranges of one set (IQL's actor and value function): each moves only its
// own values, exactly as a whole-set Adam over those values alone would.
TEST(Adam, RangeStepsOnlyItsValuesLikeAWholeSetAdamOverThem) {
  ParameterSet<double> p = makeParams(5), alone = makeParams(3);
  p.values() << 1.0, -2.0, 0.5, 3.0, -1.0;
  alone.values() = p.values().segment(1, 3);
  Adam<double> middle(p, AdamConfig<double>{}, 1, 4), whole(alone);
  const Vec<double> g = (Vec<double>(5) << 0.7, 0.3, -4.0, 0.2, 9.0).finished();
  for (int t = 0; t < 3; ++t) {
    p.grads() = g;
    alone.grads() = g.segment(1, 3);
    middle.step();
    whole.step();
  }
  EXPECT_EQ(p.values()(0), 1.0);
  EXPECT_EQ(p.values()(4), -1.0);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(p.values()(1 + i), alone.values()(i)) << "index " << i + 1;
  EXPECT_THROW(Adam<double>(p, AdamConfig<double>{}, 2, 6), std::exception);
}

// The blocks of a large set go to several threads: every block must be updated exactly once, so
// the values after some steps are those of one thread, bit for bit (a range that does not start
// at 0 and a last block that is partial included).
TEST(Adam, SeveralThreadsGiveTheBitsOfOneThread) {
  const int n = 100003, begin = 5, end = n - 7;
  auto run = [&](int threads) {
    const int saved = omp_get_max_threads();
    omp_set_num_threads(threads);
    ParameterSet<float> p;
    p.reserve("x", n);
    p.finalize();
    for (int i = 0; i < n; ++i) p.values()(i) = std::sin(0.37f * static_cast<float>(i));
    Adam<float> adam(p, AdamConfig<float>{}, begin, end);
    for (int t = 1; t <= 3; ++t) {
      for (int i = 0; i < n; ++i) p.grads()(i) = std::cos(0.11f * static_cast<float>(i * t));
      adam.step();
    }
    omp_set_num_threads(saved);
    return Vec<float>(p.values());
  };
  const Vec<float> one = run(1);
  for (int threads : {2, 3}) {
    const Vec<float> several = run(threads);
    int differing = 0;
    for (int i = 0; i < n; ++i) differing += several(i) != one(i);
    EXPECT_EQ(differing, 0) << threads << " threads";
  }
  EXPECT_EQ(one(0), std::sin(0.f));  // outside the range: untouched
  EXPECT_NE(one(begin), std::sin(0.37f * begin));
}

TEST(Adam, LearningRateChangeBetweenStepsTakesEffect) {
  ParameterSet<double> a = makeParams(4), b = makeParams(4);
  Adam<double> opt_a(a), opt_b(b);
  const Vec<double> g = (Vec<double>(4) << 1.0, -0.5, 2.0, 0.1).finished();
  a.grads() = g;
  b.grads() = g;
  opt_a.step();
  opt_b.step();
  ASSERT_EQ(a.values(), b.values());
  const Vec<double> before = a.values();
  opt_b.config().lr *= 2;
  opt_a.step();
  opt_b.step();
  const Vec<double> da = a.values() - before, db = b.values() - before;
  ASSERT_GT(da.norm(), 0.0);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(db(i), 2 * da(i), 1e-15);
}

TEST(Adam, StateSaveLoadRoundTripGivesIdenticalLaterSteps) {
  Rng rng(1);
  std::normal_distribution<float> n01;
  ParameterSet<float> p;
  p.reserve("w", 10, 3);
  p.finalize();
  for (int i = 0; i < p.size(); ++i) p.values()(i) = n01(rng);
  Adam<float> adam(p);
  auto randomGrads = [&](ParameterSet<float>& ps, int seed) {
    Rng r(seed);
    for (int i = 0; i < ps.size(); ++i) ps.grads()(i) = n01(r);
  };
  for (int s = 0; s < 3; ++s) {
    randomGrads(p, s);
    adam.step();
  }
  std::stringstream state;
  adam.save(state);
  const Vec<float> snapshot = p.values();
  for (int s = 3; s < 5; ++s) {
    randomGrads(p, s);
    adam.step();
  }

  ParameterSet<float> q;
  q.reserve("w", 10, 3);
  q.finalize();
  q.values() = snapshot;
  Adam<float> restored(q);
  restored.load(state);
  EXPECT_EQ(restored.stepCount(), 3);
  for (int s = 3; s < 5; ++s) {
    randomGrads(q, s);
    restored.step();
  }
  EXPECT_EQ(q.values(), p.values());  // bit for bit
}

TEST(Adam, LoadRejectsWrongSizeAndTruncatedState) {
  ParameterSet<double> p = makeParams(5), other = makeParams(6);
  Adam<double> adam(p), adam_other(other);
  p.grads().setOnes();
  adam.step();
  std::stringstream full;
  adam.save(full);
  const std::string bytes = full.str();

  std::stringstream wrong_size(bytes);
  EXPECT_THROW(adam_other.load(wrong_size), std::runtime_error);

  Adam<double> fresh(p);
  std::stringstream truncated(bytes.substr(0, bytes.size() - 3));
  try {
    fresh.load(truncated);
    FAIL() << "a truncated state loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("ends"), std::string::npos) << e.what();
  }
  EXPECT_EQ(fresh.stepCount(), 0);  // left untouched

  std::stringstream float_state;
  ParameterSet<float> pf;
  pf.reserve("x", 5);
  pf.finalize();
  Adam<float>(pf).save(float_state);
  EXPECT_THROW(fresh.load(float_state), std::runtime_error);
}

TEST(ClipGradNorm, ScalesLargeGradientsToExactlyMaxNorm) {
  ParameterSet<double> p = makeParams(4);
  p.grads() << 3.0, -4.0, 12.0, 0.0;  // norm 13
  const double norm = clipGradNorm(p, 2.0);
  EXPECT_DOUBLE_EQ(norm, 13.0);
  EXPECT_NEAR(p.grads().norm(), 2.0, 1e-15);
  EXPECT_NEAR(p.grads()(0), 3.0 * 2.0 / 13.0, 1e-15);
  EXPECT_NEAR(p.grads()(2), 12.0 * 2.0 / 13.0, 1e-15);
}

TEST(ClipGradNorm, LeavesSmallGradientsUntouched) {
  ParameterSet<float> p;
  p.reserve("x", 3);
  p.finalize();
  p.grads() << 0.1f, -0.2f, 0.3f;
  const Vec<float> before = p.grads();
  const float norm = clipGradNorm(p, 1.0f);
  EXPECT_FLOAT_EQ(norm, std::sqrt(0.14f));
  EXPECT_EQ(p.grads(), before);
}

}  // namespace
}  // namespace masa::nn
