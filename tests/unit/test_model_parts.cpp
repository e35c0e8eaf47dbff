// The distribution, the normalizer, the tied std and model checkpoints, each against an
// independent computation.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "common/model/actor_critic.hpp"
#include "common/model/diag_gaussian.hpp"
#include "model_test_support.hpp"

namespace masa::model {
namespace {

TEST(DiagGaussian, LogProbMatchesProductOfUnivariateDensities) {
  Rng rng(1);
  const Mat<double> mean = test::randomMatrix<double>(3, 4, rng), act = test::randomMatrix<double>(3, 4, rng);
  Vec<double> ls(3);
  ls << -0.5, 0.0, 0.4;
  Mat<double> lp(1, 4);
  gaussian::logProb<double>(mean, ls, act, lp);
  for (int b = 0; b < 4; ++b) {
    double p = 1.0;
    for (int d = 0; d < 3; ++d) {
      const double s = std::exp(ls(d)), z = (act(d, b) - mean(d, b)) / s;
      p *= std::exp(-0.5 * z * z) / (s * std::sqrt(2 * M_PI));
    }
    EXPECT_NEAR(lp(0, b), std::log(p), 1e-12);
  }
}

TEST(DiagGaussian, LogProbBackwardMatchesFiniteDifferences) {
  Rng rng(2);
  Mat<double> mean = test::randomMatrix<double>(4, 3, rng);
  const Mat<double> act = test::randomMatrix<double>(4, 3, rng), w = test::randomMatrix<double>(1, 3, rng);
  Vec<double> ls = test::randomMatrix<double>(4, 1, rng, 0.3).col(0);
  Mat<double> dmean(4, 3);
  Vec<double> dls = Vec<double>::Zero(4);
  gaussian::logProbBackward<double>(mean, ls, act, w, dmean, dls);
  Mat<double> lp(1, 3);
  auto loss = [&] {
    gaussian::logProb<double>(mean, ls, act, lp);
    return w.cwiseProduct(lp).sum();
  };
  Eigen::Map<Vec<double>> mean_flat(mean.data(), mean.size());
  const Vec<double> dmean_flat = Eigen::Map<Vec<double>>(dmean.data(), dmean.size());
  EXPECT_LT(test::checkGradient(mean_flat, dmean_flat, loss).max_relative_error, 1e-6);
  EXPECT_LT(test::checkGradient(ls, dls, loss).max_relative_error, 1e-6);
}

TEST(DiagGaussian, KlIsZeroForEqualDistributionsAndMatchesClosedForm) {
  Mat<double> m0(2, 1), m1(2, 1), out(1, 1);
  m0 << 0.3, -1.0;
  m1 << 0.5, -0.2;
  Vec<double> s0(2), s1(2);
  s0 << -0.2, 0.1;
  s1 << 0.3, -0.4;
  gaussian::kl<double>(m0, s0, m0, s0, out);
  EXPECT_NEAR(out(0, 0), 0.0, 1e-14);
  gaussian::kl<double>(m0, s0, m1, s1, out);
  double want = 0;
  for (int d = 0; d < 2; ++d) {
    const double v0 = std::exp(2 * s0(d)), v1 = std::exp(2 * s1(d));
    want += 0.5 * (std::log(v1 / v0) + (v0 + std::pow(m0(d) - m1(d), 2)) / v1 - 1);
  }
  EXPECT_NEAR(out(0, 0), want, 1e-12);
}

TEST(DiagGaussian, SamplesHaveTheRequestedMeanAndStdAndAreSeedDeterministic) {
  const int n = 20000;
  Mat<double> mean = Mat<double>::Constant(2, n, 0.0);
  mean.row(0).setConstant(1.5);
  Vec<double> ls(2);
  ls << std::log(0.5), std::log(2.0);
  Mat<double> a(2, n), b(2, n);
  Rng r1(9), r2(9);
  gaussian::sample<double>(mean, ls, r1, a);
  gaussian::sample<double>(mean, ls, r2, b);
  EXPECT_TRUE(a == b);
  EXPECT_NEAR(a.row(0).mean(), 1.5, 4 * 0.5 / std::sqrt(n));
  EXPECT_NEAR(a.row(1).mean(), 0.0, 4 * 2.0 / std::sqrt(n));
  const double sd0 = std::sqrt((a.row(0).array() - a.row(0).mean()).square().mean());
  EXPECT_NEAR(sd0, 0.5, 0.02);
  EXPECT_NEAR(gaussian::entropy<double>(ls), 2 * 0.5 * std::log(2 * M_PI * M_E) + ls.sum(), 1e-12);
}

TEST(RunningMeanStd, IncrementalUpdatesEqualOneBatch) {
  Rng rng(3);
  const Mat<double> x = test::randomMatrix<double>(4, 300, rng, 2.0, 1.0);
  RunningMeanStd<double> whole(4), parts(4);
  whole.update(x);
  parts.update(x.leftCols(100));
  parts.update(x.middleCols(100, 50));
  parts.update(x.rightCols(150));
  EXPECT_LT((whole.mean() - parts.mean()).norm(), 1e-12);
  EXPECT_LT((whole.var() - parts.var()).norm(), 1e-12);
  const Eigen::VectorXd direct_mean = x.rowwise().mean();
  EXPECT_LT((whole.mean() - direct_mean).norm(), 1e-12);
  const Eigen::VectorXd direct_var = (x.colwise() - direct_mean).array().square().rowwise().mean();
  EXPECT_LT((whole.var() - direct_var).norm(), 1e-12);
}

TEST(RunningMeanStd, SymmetricNormalizerCommutesWithEveryTransform) {
  for (const char* yaml : {test::kMirrorSpec, test::kC3Spec, test::kC4Spec}) {
    const auto spec = test::spec(yaml, "norm");
    Rng rng(4);
    RunningMeanStd<double> norm(spec.obsDim());
    std::vector<sym::SparseMap> t;
    for (int i = 0; i < spec.numAgents(); ++i) t.push_back(spec.obsTransform(i));
    norm.setSymmetry(t, spec.obsClasses());
    norm.update(test::randomMatrix<double>(spec.obsDim(), 100, rng, 3.0, 2.0));
    const Mat<double> o = test::randomMatrix<double>(spec.obsDim(), 6, rng);
    Mat<double> to(o.rows(), 6), n_to(o.rows(), 6), n_o(o.rows(), 6), t_n_o(o.rows(), 6);
    norm.normalize(o, n_o);
    for (int i = 1; i < spec.numAgents(); ++i) {
      spec.obsTransform(i).apply<double>(o, to);
      norm.normalize(to, n_to);
      spec.obsTransform(i).apply<double>(n_o, t_n_o);
      EXPECT_LT((n_to - t_n_o).cwiseAbs().maxCoeff(), 1e-12) << "transform " << i;
    }
  }
}

TEST(RunningMeanStd, PlainNormalizerDoesNotCommuteWithTransforms) {
  const auto spec = test::spec(test::kMirrorSpec, "mirror");
  Rng rng(5);
  RunningMeanStd<double> norm(spec.obsDim());
  norm.update(test::randomMatrix<double>(spec.obsDim(), 100, rng, 3.0, 2.0));
  const Mat<double> o = test::randomMatrix<double>(spec.obsDim(), 3, rng);
  Mat<double> to(o.rows(), 3), n_to(o.rows(), 3), n_o(o.rows(), 3), t_n_o(o.rows(), 3);
  spec.obsTransform(1).apply<double>(o, to);
  norm.normalize(to, n_to);
  norm.normalize(o, n_o);
  spec.obsTransform(1).apply<double>(n_o, t_n_o);
  EXPECT_GT((n_to - t_n_o).cwiseAbs().maxCoeff(), 0.1);
}

TEST(RunningMeanStd, NormalizeThenDenormalizeIsIdentityAndStateRoundTrips) {
  Rng rng(6);
  RunningMeanStd<double> a(3), b(3);
  a.update(test::randomMatrix<double>(3, 40, rng, 2.0, -1.0));
  const Mat<double> x = test::randomMatrix<double>(3, 5, rng);
  Mat<double> y(3, 5), z(3, 5);
  a.normalize(x, y);
  a.denormalize(y, z);
  EXPECT_LT((z - x).cwiseAbs().maxCoeff(), 1e-12);
  std::stringstream ss;
  a.save(ss);
  b.load(ss);
  EXPECT_EQ(a.mean(), b.mean());
  EXPECT_EQ(a.var(), b.var());
  EXPECT_EQ(a.count(), b.count());
  RunningMeanStd<double> wrong(4);
  std::stringstream ss2;
  a.save(ss2);
  EXPECT_THROW(wrong.load(ss2), std::runtime_error);
}

TEST(TiedLogStd, MasaSharesOneStdPerLimbSlotAcrossLimbs) {
  const auto spec = test::spec(test::kC4Spec, "c4");
  ModelConfig cfg;
  cfg.policy_hidden = {4};
  cfg.critic_hidden = {4};
  ActorCritic<double> m(spec, cfg);
  // 1 central + 2 limb slots = 3 parameters for 9 action dimensions.
  EXPECT_EQ(m.params().segment("policy.log_std").size(), 3);
  m.params().values().setZero();
  const auto& seg = m.params().segment("policy.log_std");
  m.params().values().segment(seg.offset, 3) << 0.1, 0.2, 0.3;
  Vec<double> ls(spec.actDim());
  m.logStd(ls);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(ls(1 + 2 * k), 0.2);
    EXPECT_EQ(ls(2 + 2 * k), 0.3);
  }
}

TEST(ActorCriticCheckpoint, SaveThenLoadGivesBitwiseIdenticalOutputs) {
  const auto spec = test::spec(test::kC3Spec, "c3");
  ModelConfig cfg;
  cfg.policy_hidden = {16, 8};
  cfg.critic_hidden = {16, 8};
  ActorCritic<float> a(spec, cfg), b(spec, cfg);
  Rng rng(8);
  a.initialize(rng);
  a.obsNormalizer().update(test::randomMatrix<float>(spec.obsDim(), 30, rng, 2.0, 1.0));
  a.valueNormalizer().update(test::randomMatrix<float>(1, 30, rng, 5.0, 3.0));
  std::stringstream ss;
  a.save(ss);
  b.load(ss, "memory");
  const Mat<float> obs = test::randomMatrix<float>(spec.obsDim(), 7, rng);
  a.forward(obs);
  const Mat<float> mean_a = a.mean(), value_a = a.value();
  b.forward(obs);
  EXPECT_TRUE(mean_a == Mat<float>(b.mean()));
  EXPECT_TRUE(value_a == Mat<float>(b.value()));
  EXPECT_EQ(a.valueNormalizer().mean(), b.valueNormalizer().mean());
}

TEST(ActorCritic, CriticValueEqualsTheTrainingForwardsValueForEveryMethod) {
  const auto spec = test::spec(test::kMirrorSpec, "mirror");
  Rng rng(10);
  const Mat<float> obs = test::randomMatrix<float>(spec.obsDim(), 6, rng);
  for (Method method : {Method::kMasa, Method::kSa, Method::kSasa, Method::kMa}) {
    ModelConfig cfg;
    cfg.method = method;
    cfg.policy_hidden = {8};
    cfg.critic_hidden = {8, 4};
    ActorCritic<float> m(spec, cfg);
    m.initialize(rng);
    m.forward(obs);
    const Mat<float> full = m.value();
    const Mat<float> only = m.criticValue(obs);
    EXPECT_TRUE(full == only) << methodName(method);
  }
}

TEST(ActorCritic, BackwardAfterActMeanOrCriticValueIsRefused) {
  const auto spec = test::spec(test::kC3Spec, "c3");
  ModelConfig cfg;
  cfg.policy_hidden = {8};
  cfg.critic_hidden = {8};
  ActorCritic<float> m(spec, cfg);
  Rng rng(11);
  m.initialize(rng);
  const Mat<float> obs = test::randomMatrix<float>(spec.obsDim(), 3, rng);
  const Mat<float> dmean = Mat<float>::Zero(spec.actDim(), 3), dvalue = Mat<float>::Zero(1, 3);
  const Vec<float> dls = Vec<float>::Zero(spec.actDim());
  m.forward(obs);
  m.criticValue(obs);
  EXPECT_THROW(m.backward(dmean, dls, dvalue), std::invalid_argument);
  m.forward(obs);
  m.actMean(obs);
  EXPECT_THROW(m.backward(dmean, dls, dvalue), std::invalid_argument);
  m.forward(obs);
  EXPECT_NO_THROW(m.backward(dmean, dls, dvalue));
}

TEST(ActorCriticCheckpoint, LoadingAnotherMethodFailsNamingBoth) {
  const auto spec = test::spec(test::kC3Spec, "c3");
  ModelConfig masa_cfg, sa_cfg;
  masa_cfg.policy_hidden = sa_cfg.policy_hidden = {8};
  masa_cfg.critic_hidden = sa_cfg.critic_hidden = {8};
  sa_cfg.method = Method::kSa;
  ActorCritic<float> a(spec, masa_cfg), b(spec, sa_cfg);
  std::stringstream ss;
  a.save(ss);
  try {
    b.load(ss, "ckpt.bin");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("ckpt.bin"), std::string::npos) << msg;
    EXPECT_NE(msg.find("masa"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace masa::model
