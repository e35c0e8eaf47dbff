// Gradients of the BC and IQL losses through the networks, against central finite differences in
// double, for SA and MASA: the value loss over the critic, the advantage-weighted actor loss over
// the policy (the advantage is a constant weight), the TD loss over both Q networks.
#include <gtest/gtest.h>

#include "learner/offline/bc_trainer.hpp"
#include "learner/offline/iql_trainer.hpp"
#include "learner/offline/normalizer_fit.hpp"
#include "offline_test_support.hpp"

namespace masa::offline {
namespace {

model::ModelConfig gradientModel(model::Method method) {
  model::ModelConfig m = test::smallOfflineModel(method, {9, 6}, {8, 5}, 1.0);
  m.init_log_std = -0.2;
  return m;
}

struct Fixture {
  sym::SymmetrySpec spec;
  model::ActorCritic<double> model;
  TwinQ<double> q, q_target;
  TransitionBatch<double> batch;

  Fixture(const char* yaml, model::Method method)
      : spec(test::spec(yaml, "spec")),
        model(spec, gradientModel(method)),
        q(spec, method, {7, 5}, nn::Activation::kElu),
        q_target(spec, method, {7, 5}, nn::Activation::kElu) {
    Rng rng(11);
    model.initialize(rng);
    q.initialize(rng);
    q_target.initialize(rng);
    const auto data = test::randomDataset(spec, 3, 4, rng);
    fitObservationNormalizer(model, data);
    Rng pick(5);
    sampleBatch(data, 6, pick, batch);
    batch.actions *= 0.3;  // keep the advantages small: weights far from their clip
  }
};

// Checks the gradient of loss() over the values [begin, end) of params.
template <typename Loss>
double worstError(nn::ParameterSet<double>& params, int begin, int end, Loss loss, double* norm) {
  loss();
  const Vec<double> analytic = params.grads().segment(begin, end - begin);
  *norm = analytic.norm();
  return test::checkGradient(params.values().segment(begin, end - begin), analytic, loss).max_relative_error;
}

const model::Method kMethods[] = {model::Method::kSa, model::Method::kMasa};
const char* const kGradientSpecs[] = {test::kMirrorSpec, test::kC3Spec};

TEST(OfflineGradient, IqlValueLossOverTheCritic) {
  for (const char* yaml : kGradientSpecs)
    for (auto method : kMethods) {
      Fixture f(yaml, method);
      IqlTrainer<double> iql(f.model, f.q, f.q_target, test::smallOfflineConfig(Algo::kIql, 10));
      double norm = 0;
      const double err = worstError(f.model.params(), 0, f.model.params().size(),
                                    [&] { return iql.valueLoss(f.batch); }, &norm);
      EXPECT_GT(norm, 1e-3) << model::methodName(method);
      EXPECT_LT(err, 1e-4) << model::methodName(method);
      // Only V learns from this loss: the policy's gradient is exactly zero.
      EXPECT_EQ(f.model.params().grads().head(f.model.policyParamCount()).cwiseAbs().maxCoeff(), 0.0);
    }
}

TEST(OfflineGradient, IqlActorLossOverThePolicy) {
  for (const char* yaml : kGradientSpecs)
    for (auto method : kMethods) {
      Fixture f(yaml, method);
      IqlTrainer<double> iql(f.model, f.q, f.q_target, test::smallOfflineConfig(Algo::kIql, 10));
      double norm = 0;
      const double err = worstError(f.model.params(), 0, f.model.policyParamCount(),
                                    [&] { return iql.actorLoss(f.batch); }, &norm);
      EXPECT_GT(norm, 1e-3) << model::methodName(method);
      EXPECT_LT(err, 1e-4) << model::methodName(method);
      // The advantage weighs samples only: nothing flows into V.
      EXPECT_EQ(f.model.params().grads().tail(f.model.params().size() - f.model.policyParamCount()).cwiseAbs().maxCoeff(),
                0.0);
    }
}

TEST(OfflineGradient, IqlTdLossOverBothQs) {
  for (const char* yaml : kGradientSpecs)
    for (auto method : kMethods) {
      Fixture f(yaml, method);
      IqlTrainer<double> iql(f.model, f.q, f.q_target, test::smallOfflineConfig(Algo::kIql, 10), 0.7);
      double norm = 0;
      const double err = worstError(f.q.params(), 0, f.q.params().size(), [&] { return iql.qLoss(f.batch); }, &norm);
      EXPECT_GT(norm, 1e-3) << model::methodName(method);
      EXPECT_LT(err, 1e-4) << model::methodName(method);
    }
}

TEST(OfflineGradient, BcLikelihoodAndMseOverThePolicy) {
  for (const char* yaml : kGradientSpecs)
    for (auto method : kMethods)
      for (BcLoss kind : {BcLoss::kGaussian, BcLoss::kMse}) {
        Fixture f(yaml, method);
        auto cfg = test::smallOfflineConfig(Algo::kBc, 10);
        cfg.bc_loss = kind;
        BcTrainer<double> bc(f.model, cfg);
        double norm = 0;
        const double err = worstError(f.model.params(), 0, f.model.params().size(), [&] { return bc.loss(f.batch); }, &norm);
        EXPECT_GT(norm, 1e-3) << model::methodName(method);
        EXPECT_LT(err, 1e-4) << model::methodName(method) << (kind == BcLoss::kMse ? " mse" : " gaussian");
      }
}

}  // namespace
}  // namespace masa::offline
