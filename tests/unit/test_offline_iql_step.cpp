// One IQL step as a whole: the target Q moves by exactly the Polyak rate towards the updated Q, the
// actor's learning rate follows the cosine over the run, only Q's parameter set and the model's
// move, and the same seed gives the same parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "learner/offline/iql_trainer.hpp"
#include "learner/offline/normalizer_fit.hpp"
#include "offline_test_support.hpp"

namespace masa::offline {
namespace {

struct SmallIqlProblem {
  sym::SymmetrySpec spec = test::spec(test::kC4Spec, "c4");
  model::ActorCritic<double> model;
  TwinQ<double> q, q_target;
  dataset::TransitionDataset data;
  SmallIqlProblem()
      : model(spec,
              [] {
                model::ModelConfig m;
                m.policy_hidden = {16};
                m.critic_hidden = {16};
                return m;
              }()),
        q(spec, model::Method::kMasa, {16, 8}, nn::Activation::kElu),
        q_target(spec, model::Method::kMasa, {16, 8}, nn::Activation::kElu) {
    Rng rng(61);
    model.initialize(rng);
    q.initialize(rng);
    q_target.initialize(rng);  // deliberately unlike q, so that the Polyak average is visible
    data = test::randomDataset(spec, 4, 8, rng);
    fitObservationNormalizer(model, data);
  }
};

TEST(IqlStep, TargetMovesByThePolyakRateTowardsTheUpdatedQ) {
  SmallIqlProblem s;
  auto cfg = test::smallOfflineConfig(Algo::kIql, 100);
  cfg.polyak = 0.05;
  IqlTrainer<double> iql(s.model, s.q, s.q_target, cfg);
  Rng rng(1);
  TransitionBatch<double> batch;
  sampleBatch(s.data, 16, rng, batch);
  const Vec<double> target_before = s.q_target.params().values(), q_before = s.q.params().values();
  iql.step(batch);
  const Vec<double> expected = 0.95 * target_before + 0.05 * s.q.params().values();
  EXPECT_GT((s.q.params().values() - q_before).norm(), 1e-6) << "Q did not learn";
  EXPECT_LT((s.q_target.params().values() - expected).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(IqlStep, ActorLearningRateFollowsTheCosineOverTheRun) {
  SmallIqlProblem s;
  auto cfg = test::smallOfflineConfig(Algo::kIql, 8);
  cfg.learning_rate = 1e-3;
  IqlTrainer<double> iql(s.model, s.q, s.q_target, cfg);
  Rng rng(2);
  TransitionBatch<double> batch;
  for (int t = 0; t < 8; ++t) {
    sampleBatch(s.data, 16, rng, batch);
    const IqlStats st = iql.step(batch);
    EXPECT_NEAR(st.actor_lr, 1e-3 * 0.5 * (1 + std::cos(std::numbers::pi * t / 8)), 1e-15) << "step " << t;
  }
}

TEST(IqlStep, TheSameSeedGivesTheSameParameters) {
  Vec<double> first;
  for (int run = 0; run < 2; ++run) {
    SmallIqlProblem s;
    IqlTrainer<double> iql(s.model, s.q, s.q_target, test::smallOfflineConfig(Algo::kIql, 10));
    Rng rng(3);
    TransitionBatch<double> batch;
    for (int t = 0; t < 5; ++t) {
      sampleBatch(s.data, 16, rng, batch);
      iql.step(batch);
    }
    Vec<double> all(s.model.params().size() + s.q.params().size());
    all << s.model.params().values(), s.q.params().values();
    if (run == 0) first = all;
    else EXPECT_EQ(all, first);
  }
}

}  // namespace
}  // namespace masa::offline
