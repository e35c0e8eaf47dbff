// The PPO minibatch loss: its gradients against central differences in every regime (ratio
// clipped or not, value clipped or not, bounds active or not), and its reported parts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/model/diag_gaussian.hpp"
#include "learner/ppo/ppo_loss.hpp"
#include "model_test_support.hpp"

namespace masa::ppo {
namespace {

constexpr int kAct = 3, kBatch = 12;

struct Inputs {
  Mat<double> mean{kAct, kBatch}, actions{kAct, kBatch}, old_mean{kAct, kBatch};
  Vec<double> log_std{kAct}, old_log_std{kAct};
  Mat<double> value{1, kBatch}, old_log_prob{1, kBatch}, advantages{1, kBatch}, old_value{1, kBatch},
      returns{1, kBatch};

  PpoLossBatch<double> batch() const {
    return {mean, log_std, value, actions, old_log_prob, old_mean, old_log_std, advantages, old_value, returns};
  }
};

PpoLossConfig lossConfig() {
  PpoLossConfig c;
  c.e_clip = 0.2;
  c.entropy_coef = 0.05;     // nonzero so that its gradient is checked too
  c.critic_coef = 2.0;
  c.bounds_loss_coef = 0.5;  // large so that the bounds gradient is not lost in the others
  c.soft_bound = 1.1;
  return c;
}

// Samples spread over the regimes, each well away from the clip and bound edges.
Inputs regimeCoveringInputs() {
  Rng rng(17);
  Inputs in;
  in.mean = test::randomMatrix<double>(kAct, kBatch, rng, 0.5);
  in.mean(0, 0) = 1.6;    // above the soft bound
  in.mean(1, 3) = -1.45;  // below it
  in.mean(2, 7) = 1.3;
  in.log_std << -0.3, 0.1, -0.6;
  in.old_log_std << -0.25, 0.05, -0.5;
  in.actions = in.mean + test::randomMatrix<double>(kAct, kBatch, rng, 0.6);
  in.old_mean = in.mean + test::randomMatrix<double>(kAct, kBatch, rng, 0.1);
  // old_logp chosen so that ratio takes these values at the current policy.
  const double ratios[kBatch] = {0.5, 0.9, 1.05, 1.5, 0.6, 1.1, 1.35, 0.95, 0.7, 1.3, 1.0, 0.75};
  const double adv[kBatch] = {1.0, -0.7, 0.4, 1.2, -1.5, 0.3, -0.8, 0.9, 0.6, -0.4, 1.1, -0.2};
  Mat<double> logp(1, kBatch);
  model::gaussian::logProb<double>(in.mean, in.log_std, in.actions, logp);
  for (int b = 0; b < kBatch; ++b) {
    in.old_log_prob(0, b) = logp(0, b) - std::log(ratios[b]);
    in.advantages(0, b) = adv[b];
  }
  // Values: |v - old_v| inside or outside e_clip, the clipped loss larger or smaller.
  const double v[kBatch] = {0.3, 1.0, -0.5, 0.8, 0.0, 2.0, -1.0, 0.5, 0.1, -0.3, 1.5, 0.7};
  const double dv[kBatch] = {0.05, 0.5, -0.6, 0.1, -0.35, 0.4, 0.15, -0.45, 0.3, -0.1, 0.55, -0.5};
  const double err[kBatch] = {0.4, -0.8, 0.3, -0.2, 0.9, 0.25, -0.6, 0.7, -0.5, 0.35, 0.45, -0.3};
  for (int b = 0; b < kBatch; ++b) {
    in.value(0, b) = v[b];
    in.old_value(0, b) = v[b] - dv[b];
    in.returns(0, b) = v[b] - err[b];
  }
  return in;
}

TEST(PpoLossGradients, MatchCentralDifferencesInEveryRegime) {
  Inputs in = regimeCoveringInputs();
  const PpoLossConfig cfg = lossConfig();
  PpoLoss<double> loss(cfg, kAct, kBatch);
  const PpoLossStats st = loss.compute(in.batch());

  // The case covers every regime.
  int ratio_clipped_flat = 0, ratio_live = 0, value_clipped_flat = 0, value_live = 0, bounds_active = 0;
  Mat<double> logp(1, kBatch);
  model::gaussian::logProb<double>(in.mean, in.log_std, in.actions, logp);
  for (int b = 0; b < kBatch; ++b) {
    const double ratio = std::exp(logp(0, b) - in.old_log_prob(0, b)), a = in.advantages(0, b);
    const double clipped = std::clamp(ratio, 1 - cfg.e_clip, 1 + cfg.e_clip);
    (-a * clipped > -a * ratio ? ratio_clipped_flat : ratio_live)++;
    const double v = in.value(0, b), ov = in.old_value(0, b), ret = in.returns(0, b);
    const double vc = ov + std::clamp(v - ov, -cfg.e_clip, cfg.e_clip);
    ((vc - ret) * (vc - ret) > (v - ret) * (v - ret) ? value_clipped_flat : value_live)++;
    for (int d = 0; d < kAct; ++d) bounds_active += std::abs(in.mean(d, b)) > cfg.soft_bound ? 1 : 0;
  }
  EXPECT_GE(ratio_clipped_flat, 2);
  EXPECT_GE(ratio_live, 2);
  EXPECT_GE(value_clipped_flat, 2);
  EXPECT_GE(value_live, 2);
  EXPECT_GE(bounds_active, 3);
  EXPECT_GT(st.clip_fraction, 0.0);
  EXPECT_LT(st.clip_fraction, 1.0);

  // x = [mean, log_std, value]; loss(x) = total.
  const int nm = kAct * kBatch;
  Vec<double> x(nm + kAct + kBatch), analytic(x.size());
  x << in.mean.reshaped(), in.log_std, in.value.reshaped();
  analytic << loss.dmean().reshaped(), loss.dlogStd(), loss.dvalue().reshaped();
  PpoLoss<double> probe(cfg, kAct, kBatch);
  auto total = [&]() {
    Inputs p = in;
    p.mean = x.head(nm).reshaped(kAct, kBatch);
    p.log_std = x.segment(nm, kAct);
    p.value = x.tail(kBatch).reshaped(1, kBatch);
    return probe.compute(p.batch()).total_loss;
  };
  // The floor keeps rounding noise on the exactly-zero gradients of flat samples from counting.
  const auto r = test::checkGradient(x, analytic, total, 1e-5, 1e-6);
  EXPECT_LT(r.max_relative_error, 1e-4) << "worst index " << r.worst_index;
  EXPECT_GT(r.analytic_norm, 0.1);
}

TEST(PpoLossGradients, ClippedRatioAndValueGiveNoGradient) {
  Inputs in = regimeCoveringInputs();
  PpoLossConfig cfg = lossConfig();
  cfg.bounds_loss_coef = 0;
  cfg.entropy_coef = 0;
  PpoLoss<double> loss(cfg, kAct, kBatch);
  loss.compute(in.batch());
  // Sample 3: ratio 1.5 with A > 0 (clipped term wins); sample 2: v - old_v = -0.6 with the clipped
  // value farther from the return.
  EXPECT_EQ(loss.dmean().col(3).norm(), 0.0);
  EXPECT_EQ(loss.dvalue()(0, 2), 0.0);
  // Sample 0: ratio 0.5 with A > 0: the unclipped term wins and drives the ratio up.
  EXPECT_GT(loss.dmean().col(0).norm(), 0.0);
}

TEST(PpoLossParts, MatchTheirDefinitionsAtAnUnchangedPolicy) {
  Inputs in = regimeCoveringInputs();
  in.old_mean = in.mean;
  in.old_log_std = in.log_std;
  model::gaussian::logProb<double>(in.mean, in.log_std, in.actions, in.old_log_prob);
  in.old_value = in.value;
  const PpoLossConfig cfg = lossConfig();
  PpoLoss<double> loss(cfg, kAct, kBatch);
  const PpoLossStats st = loss.compute(in.batch());
  EXPECT_NEAR(st.actor_loss, -in.advantages.mean(), 1e-12);  // ratio 1
  EXPECT_NEAR(st.critic_loss, (in.value - in.returns).squaredNorm() / kBatch, 1e-12);
  EXPECT_NEAR(st.kl, 0.0, 1e-12);
  EXPECT_EQ(st.clip_fraction, 0.0);
  EXPECT_NEAR(st.entropy, model::gaussian::entropy<double>(in.log_std), 1e-12);
  double bounds = 0;
  for (int b = 0; b < kBatch; ++b)
    for (int d = 0; d < kAct; ++d) {
      const double mu = in.mean(d, b);
      bounds += mu > 1.1 ? (mu - 1.1) * (mu - 1.1) : (mu < -1.1 ? (mu + 1.1) * (mu + 1.1) : 0.0);
    }
  EXPECT_NEAR(st.bounds_loss, bounds / kBatch, 1e-12);
  EXPECT_GT(st.bounds_loss, 0.0);
  EXPECT_NEAR(st.total_loss, st.actor_loss + 0.5 * cfg.critic_coef * st.critic_loss - cfg.entropy_coef * st.entropy +
                                 cfg.bounds_loss_coef * st.bounds_loss,
              1e-12);
}

TEST(PpoLossParts, KlIsOldToNewAndPositiveWhenThePolicyMoves) {
  Inputs in = regimeCoveringInputs();
  PpoLoss<double> loss(lossConfig(), kAct, kBatch);
  const PpoLossStats st = loss.compute(in.batch());
  Mat<double> kl(1, kBatch);
  model::gaussian::kl<double>(in.old_mean, in.old_log_std, in.mean, in.log_std, kl);
  EXPECT_GT(st.kl, 0.0);
  EXPECT_NEAR(st.kl, kl.mean(), 1e-12);
}

// With max_policy_lag > 0 a minibatch mixes samples of several policy versions: each sample's KL
// must be measured from its own behaviour std, not from one shared std.
TEST(PpoLossParts, KlUsesEachSamplesOwnBehaviourStd) {
  Inputs in = regimeCoveringInputs();
  Mat<double> per_sample(kAct, kBatch);
  for (int b = 0; b < kBatch; ++b) per_sample.col(b) = in.old_log_std.array() + 0.1 * b;
  const PpoLossBatch<double> batch{in.mean,     in.log_std,    in.value,      in.actions,    in.old_log_prob,
                                   in.old_mean, per_sample,    in.advantages, in.old_value,  in.returns};
  PpoLoss<double> loss(lossConfig(), kAct, kBatch);
  const PpoLossStats st = loss.compute(batch);
  double expected = 0;
  for (int b = 0; b < kBatch; ++b) {
    Mat<double> one(1, 1);
    model::gaussian::kl<double>(in.old_mean.col(b), per_sample.col(b), in.mean.col(b), in.log_std, one);
    expected += one(0, 0);
  }
  EXPECT_NEAR(st.kl, expected / kBatch, 1e-12);
  // The shared-std answer (every sample with sample 0's std) is measurably different.
  Mat<double> shared(1, kBatch);
  model::gaussian::kl<double>(in.old_mean, per_sample.col(0), in.mean, in.log_std, shared);
  EXPECT_GT(std::abs(st.kl - shared.mean()), 1e-3);
}

}  // namespace
}  // namespace masa::ppo

namespace masa::ppo {
namespace {

// Inside the value clip range the clipped value is the value itself, so both terms of the max and
// their gradients are equal: every sample gets the full critic gradient 2 (v - R). In floats
// old_v + (v - old_v) - R rounds differently from v - R, and the clipped term used to "win" by an
// ulp in about a third of the samples and take their gradient to 0 (a real loss of critic signal,
// found when two data-parallel ranks and one learner parted at the second minibatch).
TEST(PpoLossGradients, InsideTheValueClipRangeEverySampleGetsTheFullCriticGradient) {
  constexpr int kSamples = 4096;
  PpoLossConfig cfg;
  cfg.clip_value = true;
  cfg.critic_coef = 2.0;
  PpoLoss<float> loss(cfg, 1, kSamples);
  Rng rng(3);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  Mat<float> mean = Mat<float>::Zero(1, kSamples), actions = Mat<float>::Zero(1, kSamples);
  Mat<float> value(1, kSamples), old_value(1, kSamples), returns(1, kSamples), zeros = Mat<float>::Zero(1, kSamples);
  Vec<float> log_std = Vec<float>::Zero(1);
  // Normalized values and small errors, as the critic sees them late in training: there the
  // rounding put the clipped term ahead in about 6% of the samples (1 in 4000 at values of 3).
  for (int b = 0; b < kSamples; ++b) {
    value(0, b) = 0.3f * u(rng);
    old_value(0, b) = value(0, b) - 0.9f * static_cast<float>(cfg.e_clip) * u(rng);  // |v - old_v| < e
    returns(0, b) = value(0, b) + 0.1f * u(rng);
  }
  loss.compute({mean, log_std, value, actions, zeros, mean, log_std, zeros, old_value, returns});
  const float scale = 0.5f * static_cast<float>(cfg.critic_coef) / kSamples;
  int wrong = 0;
  for (int b = 0; b < kSamples; ++b) {
    const float expected = scale * 2.f * (value(0, b) - returns(0, b));
    // To within the rounding of old_v + (v - old_v) (values below 1: an error of 1e-6 is 16 ulps).
    if (std::abs(loss.dvalue()(0, b) - expected) > scale * 2.f * 1e-6f) ++wrong;
  }
  EXPECT_EQ(wrong, 0) << "of " << kSamples << " samples inside the clip range";
}

}  // namespace
}  // namespace masa::ppo
