// One PPO update on synthetic batches: direction of the policy and value changes, wiring of
// time-outs into GAE, determinism, and no allocation in the minibatch loop.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "alloc_counter.hpp"
#include "common/model/diag_gaussian.hpp"
#include "learner/ppo/ppo_trainer.hpp"
#include "model_test_support.hpp"

namespace masa::ppo {
namespace {

constexpr int kEnvs = 32, kHorizon = 4;
constexpr int kInvariantObs = 1;  // torso_z of the mirror spec: unchanged by the mirror

config::PpoConfig smallPpo() {
  config::PpoConfig c;
  c.minibatch_size = 32;
  c.mini_epochs = 4;
  c.learning_rate = 1e-3;
  c.lr_schedule = "fixed";
  return c;
}

struct Rig {
  explicit Rig(model::Method method, const config::PpoConfig& ppo = smallPpo(), std::uint64_t seed = 5)
      : spec(test::spec(test::kMirrorSpec, "mirror")) {
    model::ModelConfig mc;
    mc.method = method;
    mc.policy_hidden = {32, 32};
    mc.critic_hidden = {32, 32};
    model = std::make_unique<model::ActorCritic<float>>(spec, mc);
    Rng rng(seed);
    model->initialize(rng);
    adam = std::make_unique<nn::Adam<float>>(model->params());
    trainer = std::make_unique<PpoTrainer>(*model, *adam, ppo);
    buffer = std::make_unique<RolloutBuffer>(kEnvs, kHorizon, spec.obsDim(), spec.actDim());
  }
  sym::SymmetrySpec spec;
  std::unique_ptr<model::ActorCritic<float>> model;
  std::unique_ptr<nn::Adam<float>> adam;
  std::unique_ptr<PpoTrainer> trainer;
  std::unique_ptr<RolloutBuffer> buffer;
};

// One-step episodes (every step terminates) with reward +-1 by the sign of an invariant
// observation, actions sampled from the model. The obs normalizer is first fed this batch, so the
// update's own normalizer step leaves it (nearly) unchanged and only learning moves the policy.
void fillOneStepBatch(Rig& s, Rng& rng) {
  RolloutBuffer& b = *s.buffer;
  b.clear();
  b.obs() = test::randomMatrix<float>(b.obsDim(), b.size(), rng);
  b.bootstrapObs() = test::randomMatrix<float>(b.obsDim(), b.numEnvs(), rng);
  s.model->obsNormalizer().update(b.obs());
  b.means() = s.model->actMean(b.obs());
  Vec<float> log_std(b.actDim());
  s.model->logStd(log_std);
  b.envLogStds().colwise() = log_std;
  model::gaussian::sample<float>(b.means(), log_std, rng, b.actions());
  model::gaussian::logProb<float>(b.means(), log_std, b.actions(), b.logProbs());
  for (int t = 0; t < b.horizon(); ++t)
    for (int e = 0; e < b.numEnvs(); ++e) b.rewards()(t, e) = b.obs()(kInvariantObs, b.column(t, e)) > 0 ? 1.f : -1.f;
  b.terminated().setOnes();
  b.truncated().setZero();
}

Mat<float> logProbs(Rig& s) {
  const RolloutBuffer& b = *s.buffer;
  const Mat<float> mean = s.model->actMean(b.obs());
  Vec<float> ls(b.actDim());
  s.model->logStd(ls);
  Mat<float> lp(1, b.size());
  model::gaussian::logProb<float>(mean, ls, b.actions(), lp);
  return lp;
}

// Mean squared error of the critic, in real units, against the one-step returns (the rewards).
double valueError(Rig& s) {
  RolloutBuffer& b = *s.buffer;
  s.model->forward(b.obs());
  Mat<float> v = s.model->value();
  s.model->valueNormalizer().denormalize(v, v);
  double err = 0;
  for (int c = 0; c < b.size(); ++c) {
    const double d = v(0, c) - b.rewards().data()[c];
    err += d * d;
  }
  return err / b.size();
}

class PpoTrainerUpdate : public ::testing::TestWithParam<model::Method> {};

TEST_P(PpoTrainerUpdate, RaisesLogProbOfPositiveAdvantageActionsLowersNegativeAndFitsTheValue) {
  config::PpoConfig ppo = smallPpo();
  ppo.learning_rate = 3e-3;
  Rig s(GetParam(), ppo);
  Rng rng(11);
  fillOneStepBatch(s, rng);
  const Mat<float> before = logProbs(s);
  const double value_error_before = valueError(s);
  const PpoStats st = s.trainer->update(*s.buffer, rng);
  const Mat<float> after = logProbs(s);
  const double value_error_after = valueError(s);

  double up_pos = 0, up_neg = 0;
  int n_pos = 0, n_neg = 0;
  for (int c = 0; c < s.buffer->size(); ++c) {
    const double delta = after(0, c) - before(0, c);
    const bool positive = s.buffer->advantages().data()[c] > 0;
    (positive ? up_pos : up_neg) += delta;
    (positive ? n_pos : n_neg)++;
  }
  ASSERT_GT(n_pos, 10);
  ASSERT_GT(n_neg, 10);
  EXPECT_GT(up_pos / n_pos, 0.0);
  EXPECT_LT(up_neg / n_neg, 0.0);
  EXPECT_LT(value_error_after, 0.9 * value_error_before);
  EXPECT_EQ(st.minibatches, 4 * 4);
  EXPECT_GT(st.kl, 0.0);
  EXPECT_GT(st.grad_norm, 0.0);
  std::printf("value error %.3f -> %.3f, mean dlogp A>0 %.4f A<0 %.4f\n", value_error_before, value_error_after,
              up_pos / n_pos, up_neg / n_neg);
}

INSTANTIATE_TEST_SUITE_P(PpoMethods, PpoTrainerUpdate,
                         ::testing::Values(model::Method::kMasa, model::Method::kSa, model::Method::kSasa,
                                           model::Method::kMa),
                         [](const auto& info) { return model::methodName(info.param); });

// rl_games' KL for the adaptive lr measures one mini-epoch's drift: after a minibatch is used, its
// stored mean and std become the policy's at that visit. A batch collected by a policy far from the
// model (means shifted by 1) has a large KL on the first visit; on the second visit the KL must only
// measure the small step in between, not the distance to the collection policy again.
TEST(PpoTrainerKl, SecondMiniEpochMeasuresTheDriftSinceTheFirstNotSinceCollection) {
  config::PpoConfig ppo = smallPpo();
  ppo.minibatch_size = kEnvs * kHorizon;  // one minibatch per mini-epoch
  ppo.learning_rate = 1e-4;
  auto firstVisitKl = [&](int mini_epochs) {
    config::PpoConfig c = ppo;
    c.mini_epochs = mini_epochs;
    Rig s(model::Method::kSa, c);
    Rng rng(11);
    fillOneStepBatch(s, rng);
    s.buffer->means().array() += 1.0f;  // behaviour policy != the model
    return s.trainer->update(*s.buffer, rng);
  };
  const PpoStats one = firstVisitKl(1), two = firstVisitKl(2);
  ASSERT_EQ(two.minibatches, 2);
  const double kl_first = one.kl;                  // KL(collection || model) on the first visit
  const double kl_second = 2.0 * two.kl - one.kl;  // the second visit's KL
  EXPECT_GT(kl_first, 0.2);  // every action shifted by one std: 0.5 per action
  EXPECT_GE(kl_second, 0.0);
  EXPECT_LT(kl_second, 0.01 * kl_first) << "the second mini-epoch's KL still measures the distance to collection";
}

TEST(PpoTrainerPrepare, TimeOutsBootstrapFromFinalObsAndHorizonEndFromBootstrapObs) {
  config::PpoConfig ppo = smallPpo();
  ppo.normalize_value = false;  // values are then the critic's outputs as they are
  Rig s(model::Method::kSa, ppo);
  Rng rng(3);
  fillOneStepBatch(s, rng);
  RolloutBuffer& b = *s.buffer;
  b.terminated().setZero();
  b.truncated()(1, 4) = 1;
  const Mat<float> final_obs = test::randomMatrix<float>(b.obsDim(), 1, rng, 3.0);
  b.addFinalObs(1, 4, final_obs);
  s.trainer->prepare(b);

  auto value = [&](const Mat<float>& obs) {
    s.model->forward(obs);
    return static_cast<double>(s.model->value()(0, 0));
  };
  const double g = ppo.gamma, gl = ppo.gamma * ppo.tau;
  const double v1 = value(b.obs().col(b.column(1, 4))), v2 = value(b.obs().col(b.column(2, 4)));
  const double v_final = value(final_obs), v_boot = value(b.bootstrapObs().col(4));
  const double v3 = value(b.obs().col(b.column(3, 4)));
  // Step 1 of env 4 ends its episode by time-out: bootstrap V(final obs), nothing from step 2.
  EXPECT_NEAR(b.advantages()(1, 4), b.rewards()(1, 4) + g * v_final - v1, 1e-5);
  // Step 3 continues into the bootstrap observation.
  const double d3 = b.rewards()(3, 4) + g * v_boot - v3;
  EXPECT_NEAR(b.advantages()(3, 4), d3, 1e-5);
  EXPECT_NEAR(b.advantages()(2, 4), b.rewards()(2, 4) + g * v3 - v2 + gl * d3, 1e-5);
}

TEST(PpoTrainerPrepare, ValuesAreInRealUnitsOfTheValueNormalizerBeforeItsUpdate) {
  Rig s(model::Method::kMasa);
  Rng rng(6);
  for (int k = 0; k < 2; ++k) {  // moves the value normalizer away from (0, 1)
    fillOneStepBatch(s, rng);
    s.buffer->rewards().array() = 5.f * s.buffer->rewards().array() + 3.f;
    s.trainer->update(*s.buffer, rng);
  }
  const model::RunningMeanStd<float> before = s.model->valueNormalizer();
  ASSERT_GT(before.mean()(0), 1.0);
  fillOneStepBatch(s, rng);
  s.trainer->prepare(*s.buffer);
  s.model->forward(s.buffer->obs());
  Mat<float> expected = s.model->value();
  before.denormalize(expected, expected);
  for (int c = 0; c < s.buffer->size(); ++c)
    ASSERT_NEAR(s.buffer->values().data()[c], expected(0, c), 1e-4 * (1 + std::abs(expected(0, c)))) << c;
  EXPECT_NE(s.model->valueNormalizer().mean()(0), before.mean()(0));  // then fed the returns
}

TEST(PpoTrainerPrepare, RejectsTimeOutWithoutFinalObs) {
  Rig s(model::Method::kSa);
  Rng rng(3);
  fillOneStepBatch(s, rng);
  s.buffer->truncated()(0, 0) = 1;
  EXPECT_THROW(s.trainer->prepare(*s.buffer), std::invalid_argument);
}

// A batch short of environments lost on the network (the learner's runner.min_batch_fraction):
// 20 of 32 environments x 4 steps = 80 samples, minibatch_size 32. It trains in ceil(80 / 32) = 3
// minibatches of 26-27 samples per mini-epoch (every sample once, none a tiny last step), learns
// like a full batch, and the next full batch goes back to whole minibatches.
TEST(PpoTrainerShortBatch, SplitsIntoEqualMinibatchesAndLearns) {
  Rig s(model::Method::kMasa);
  Rng rng(13);
  s.buffer->setNumEnvs(20);
  ASSERT_EQ(s.buffer->size(), 80);
  fillOneStepBatch(s, rng);
  const Mat<float> lp_before = logProbs(s);
  const PpoStats st = s.trainer->update(*s.buffer, rng);
  EXPECT_EQ(st.minibatches, 3 * 4);
  EXPECT_TRUE(std::isfinite(st.total_loss) && std::isfinite(st.kl)) << st.total_loss << " " << st.kl;
  const Mat<float> lp_after = logProbs(s);
  double up = 0, down = 0;  // log-prob change of the actions the advantage favoured / disfavoured
  for (int t = 0; t < s.buffer->horizon(); ++t)
    for (int e = 0; e < s.buffer->numEnvs(); ++e) {
      const int c = s.buffer->column(t, e);
      (s.buffer->rewards()(t, e) > 0 ? up : down) += lp_after(0, c) - lp_before(0, c);
    }
  EXPECT_GT(up, 0.0);
  EXPECT_LT(down, 0.0);

  s.buffer->setNumEnvs(kEnvs);
  fillOneStepBatch(s, rng);
  EXPECT_EQ(s.trainer->update(*s.buffer, rng).minibatches, (kEnvs * kHorizon / 32) * 4);
}

bool bitwiseEqual(const Vec<float>& a, const Vec<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), sizeof(float) * a.size()) == 0;
}

Vec<float> paramsAfterTwoUpdates(model::Method method, std::uint64_t shuffle_seed) {
  config::PpoConfig ppo = smallPpo();
  ppo.lr_schedule = "adaptive";
  Rig s(method, ppo);
  Rng data_rng(21), shuffle_rng(shuffle_seed);
  for (int k = 0; k < 2; ++k) {
    fillOneStepBatch(s, data_rng);
    s.trainer->update(*s.buffer, shuffle_rng);
  }
  return s.model->params().values();
}

TEST(PpoTrainerDeterminism, SameSeedAndInputsGiveBitwiseIdenticalParameters) {
  for (auto method : {model::Method::kMasa, model::Method::kSasa}) {
    const Vec<float> a = paramsAfterTwoUpdates(method, 8), b = paramsAfterTwoUpdates(method, 8);
    EXPECT_TRUE(bitwiseEqual(a, b)) << model::methodName(method);
    // The shuffle seed matters, so the comparison above can fail.
    const Vec<float> c = paramsAfterTwoUpdates(method, 9);
    EXPECT_FALSE(bitwiseEqual(a, c)) << model::methodName(method);
  }
}

class PpoTrainerAllocation : public ::testing::TestWithParam<model::Method> {};

TEST_P(PpoTrainerAllocation, NoneInTheMinibatchLoopAfterTheFirstUpdate) {
  if (!test::allocationCountingEnabled()) GTEST_SKIP() << "malloc is owned by a sanitizer";
  config::PpoConfig ppo = smallPpo();
  ppo.lr_schedule = "adaptive";
  Rig s(GetParam(), ppo);
  Rng rng(4);
  fillOneStepBatch(s, rng);
  s.trainer->update(*s.buffer, rng);
  fillOneStepBatch(s, rng);
  s.trainer->prepare(*s.buffer);
  const long before = test::allocationCount();
  const PpoStats st = s.trainer->optimize(*s.buffer, rng);
  EXPECT_EQ(test::allocationCount() - before, 0);
  EXPECT_EQ(st.minibatches, 16);
}

INSTANTIATE_TEST_SUITE_P(PpoMethods, PpoTrainerAllocation,
                         ::testing::Values(model::Method::kMasa, model::Method::kSa, model::Method::kSasa,
                                           model::Method::kMa),
                         [](const auto& info) { return model::methodName(info.param); });

}  // namespace
}  // namespace masa::ppo
