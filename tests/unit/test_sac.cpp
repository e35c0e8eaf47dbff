// The off-policy learner (learner/sac): the replay buffer's ring, uniform draws and n-step returns
// (terminations stop, time-outs bootstrap from the truncated step's own next observation); the
// squashed Gaussian's log-prob against the formula; MASA's SAC policy equivariant (mean, log-std,
// sampled action and log-prob) and its twin Q invariant to 1e-5 in float, where SA fails the same
// checks; the losses against hand-computed values; every loss's gradient against central
// differences in double for the four methods; and a resumed trainer taking the same next step.
#include <gtest/gtest.h>

#include <sstream>

#include "common/config/run_config.hpp"
#include "common/core/config_error.hpp"
#include "config_error_support.hpp"
#include "learner/sac/replay_buffer.hpp"
#include "learner/sac/sac_critic_maps.hpp"
#include "learner/sac/sac_losses.hpp"
#include "learner/sac/sac_trainer.hpp"
#include "common/model/squashed_gaussian.hpp"
#include "model_test_support.hpp"

namespace masa::sac {
namespace {

using model::Method;

// ---------------------------------------------------------------- replay buffer

// Step k of a stream: observation (k, -k), action k/10, reward k+1; next observation (k + 0.5, 0).
void addStep(ReplayBuffer& rb, int k, bool terminated = false, bool truncated = false) {
  const float obs[2] = {float(k), float(-k)}, next[2] = {k + 0.5f, 0.0f}, act[1] = {k / 10.0f};
  rb.add(obs, act, k + 1.0, next, terminated, truncated);
}

TEST(SacReplay, WrapAroundKeepsTheNewestCapacityStepsAndSamplesThemUniformly) {
  ReplayBuffer rb(2, 1, 5);
  for (int k = 0; k < 7; ++k) addStep(rb, k);
  EXPECT_EQ(rb.size(), 5);
  EXPECT_EQ(rb.added(), 7);
  EXPECT_EQ(rb.obsAt(rb.slotOfAge(0))[0], 6.0f);  // newest
  EXPECT_EQ(rb.obsAt(rb.slotOfAge(4))[0], 2.0f);  // oldest kept; steps 0 and 1 overwritten
  Rng rng(3);
  ReplayBatch<float> batch;
  std::vector<int> count(7, 0);
  for (int round = 0; round < 50; ++round) {
    rb.sample(100, 1, 0.9, rng, batch);
    for (int b = 0; b < batch.size(); ++b) ++count[static_cast<int>(batch.obs(0, b))];
  }
  EXPECT_EQ(count[0] + count[1], 0);
  for (int k = 2; k < 7; ++k) {  // 5000 draws over 5 slots: 1000 each, sd 28
    EXPECT_GT(count[k], 880) << k;
    EXPECT_LT(count[k], 1120) << k;
  }
}

TEST(SacReplay, SamplesAreTheSlotsTheGeneratorDrawsAndTheSameSeedGivesTheSameBatch) {
  ReplayBuffer rb(2, 1, 8);
  for (int k = 0; k < 8; ++k) addStep(rb, k);
  Rng a(17), b(17), expect(17);
  ReplayBatch<float> ba, bb;
  rb.sample(32, 1, 0.9, a, ba);
  rb.sample(32, 1, 0.9, b, bb);
  EXPECT_EQ(ba.obs, bb.obs);
  std::uniform_int_distribution<long long> pick(0, 7);
  for (int j = 0; j < 32; ++j) EXPECT_EQ(ba.obs(0, j), float(pick(expect))) << j;
  Rng c(18);
  rb.sample(32, 1, 0.9, c, bb);
  EXPECT_NE(ba.obs, bb.obs);
}

// Stream: steps 0 1 2 | 3 4 | 5 6 7 ...: step 2 terminated, step 4 truncated (time-out), 7 newest.
TEST(SacReplay, NStepReturnsStopAtTerminationsAndBootstrapAtTimeOutsFromTheTruncatedStepsNextObservation) {
  ReplayBuffer rb(2, 1, 16);
  for (int k = 0; k < 8; ++k) addStep(rb, k, k == 2, k == 4);
  ReplayBatch<double> batch;
  batch.resize(2, 1, 6);
  const int slots[6] = {0, 1, 2, 3, 5, 6};
  for (int j = 0; j < 6; ++j) rb.nStep(slots[j], 3, 0.5, batch, j);
  // rewards are k + 1
  EXPECT_DOUBLE_EQ(batch.rewards(0, 0), 1 + 0.5 * 2 + 0.25 * 3);  // 0,1,2 then the termination
  EXPECT_DOUBLE_EQ(batch.discount(0, 0), 0.0);
  EXPECT_DOUBLE_EQ(batch.next_obs(0, 0), 2.5);
  EXPECT_DOUBLE_EQ(batch.rewards(0, 1), 2 + 0.5 * 3);
  EXPECT_DOUBLE_EQ(batch.discount(0, 1), 0.0);
  EXPECT_DOUBLE_EQ(batch.rewards(0, 2), 3);
  EXPECT_DOUBLE_EQ(batch.discount(0, 2), 0.0);
  EXPECT_DOUBLE_EQ(batch.rewards(0, 3), 4 + 0.5 * 5);  // 3, 4 then the time-out: bootstrap g^2
  EXPECT_DOUBLE_EQ(batch.discount(0, 3), 0.25);
  EXPECT_DOUBLE_EQ(batch.next_obs(0, 3), 4.5);  // step 4's own next observation, not step 5's
  EXPECT_DOUBLE_EQ(batch.rewards(0, 4), 6 + 0.5 * 7 + 0.25 * 8);  // a full 3 steps: g^3
  EXPECT_DOUBLE_EQ(batch.discount(0, 4), 0.125);
  EXPECT_DOUBLE_EQ(batch.next_obs(0, 4), 7.5);
  EXPECT_DOUBLE_EQ(batch.rewards(0, 5), 7 + 0.5 * 8);  // cut at the newest step: g^2 from its next
  EXPECT_DOUBLE_EQ(batch.discount(0, 5), 0.25);
  EXPECT_DOUBLE_EQ(batch.actions(0, 5), 0.6f);
  EXPECT_DOUBLE_EQ(batch.obs(0, 5), 6);

  ReplayBuffer both(2, 1, 4);  // a fall on the time limit's step: terminated wins, no bootstrap
  addStep(both, 0, true, true);
  both.nStep(0, 3, 0.5, batch, 0);
  EXPECT_DOUBLE_EQ(batch.discount(0, 0), 0.0);
}

TEST(SacReplay, NStepFollowsTheRingAcrossItsEndButNeverPastTheNewestStep) {
  ReplayBuffer rb(2, 1, 4);
  for (int k = 0; k < 6; ++k) addStep(rb, k);  // slots 2, 3, 0, 1 hold steps 2, 3, 4, 5
  ReplayBatch<double> batch;
  batch.resize(2, 1, 2);
  rb.nStep(3, 3, 0.5, batch, 0);  // step 3: 3, 4 (slot 0), 5 (slot 1)
  EXPECT_DOUBLE_EQ(batch.obs(0, 0), 3);
  EXPECT_DOUBLE_EQ(batch.rewards(0, 0), 4 + 0.5 * 5 + 0.25 * 6);
  EXPECT_DOUBLE_EQ(batch.next_obs(0, 0), 5.5);
  rb.nStep(0, 3, 0.5, batch, 1);  // step 4: only 5 follows, slot 2 is the older step 2
  EXPECT_DOUBLE_EQ(batch.rewards(0, 1), 5 + 0.5 * 6);
  EXPECT_DOUBLE_EQ(batch.discount(0, 1), 0.25);
  EXPECT_DOUBLE_EQ(batch.next_obs(0, 1), 5.5);
}

TEST(SacReplay, SaveAndLoadGiveTheSameSamples) {
  ReplayBuffer rb(2, 1, 5);
  for (int k = 0; k < 7; ++k) addStep(rb, k, k == 3);
  std::stringstream ss;
  rb.save(ss);
  ReplayBuffer back(2, 1, 5);
  back.load(ss);
  Rng a(5), b(5);
  ReplayBatch<float> x, y;
  rb.sample(20, 3, 0.9, a, x);
  back.sample(20, 3, 0.9, b, y);
  EXPECT_EQ(x.obs, y.obs);
  EXPECT_EQ(x.rewards, y.rewards);
  EXPECT_EQ(x.discount, y.discount);
  EXPECT_EQ(x.next_obs, y.next_obs);
  ReplayBuffer other(2, 1, 6);
  std::stringstream again;
  rb.save(again);
  EXPECT_THROW(other.load(again), std::runtime_error);
}

// ---------------------------------------------------------------- squashed Gaussian

TEST(SacSquashedGaussian, LogProbIsTheGaussianDensityWithTheTanhJacobian) {
  Mat<double> mean(2, 1), log_std(2, 1), eps(2, 1), a(2, 1), lp(1, 1);
  mean << 0.3, -1.2;
  log_std << -0.5, 0.4;
  eps << 0.7, -0.2;
  squashed_gaussian::sample<double>(mean, log_std, eps, a, lp);
  double expect = 0;
  for (int d = 0; d < 2; ++d) {
    const double u = mean(d) + std::exp(log_std(d)) * eps(d);
    EXPECT_NEAR(a(d), std::tanh(u), 1e-15);
    expect += -0.5 * eps(d) * eps(d) - log_std(d) - 0.5 * std::log(2 * M_PI) - std::log(1 - std::tanh(u) * std::tanh(u));
  }
  EXPECT_NEAR(lp(0), expect, 1e-12);
  // Far in the tail tanh(u) rounds to 1; the stable form still gives log(1 - tanh^2 u) = 2 log 2 - 2u.
  mean << 20.0, 0.0;
  eps << 0.0, 0.0;
  log_std << 0.0, 0.0;
  squashed_gaussian::sample<double>(mean, log_std, eps, a, lp);
  EXPECT_NEAR(lp(0), -2 * 0.5 * std::log(2 * M_PI) - (2 * std::log(2.0) - 40.0) - 0.0, 1e-9);
}

TEST(SacSquashedGaussian, ReparameterizedGradientsMatchFiniteDifferences) {
  Rng rng(2);
  Mat<double> mean = Mat<double>::Random(3, 4), log_std = 0.5 * Mat<double>::Random(3, 4), eps(3, 4);
  squashed_gaussian::drawNoise<double>(rng, eps);
  const Mat<double> ca = Mat<double>::Random(3, 4), cl = Mat<double>::Random(1, 4);
  Mat<double> a(3, 4), lp(1, 4), dm(3, 4), dl(3, 4);
  auto loss = [&] {
    squashed_gaussian::sample<double>(mean, log_std, eps, a, lp);
    return ca.cwiseProduct(a).sum() + cl.cwiseProduct(lp).sum();
  };
  loss();
  squashed_gaussian::sampleBackward<double>(log_std, eps, a, ca, cl, dm, dl);
  const Vec<double> gm = Eigen::Map<Vec<double>>(dm.data(), 12);
  const auto rm = test::checkGradient(Eigen::Map<Vec<double>>(mean.data(), 12), gm, loss);
  const auto rl = test::checkGradient(Eigen::Map<Vec<double>>(log_std.data(), 12), Eigen::Map<Vec<double>>(dl.data(), 12), loss);
  EXPECT_LT(rm.max_relative_error, 1e-6);
  EXPECT_LT(rl.max_relative_error, 1e-6);
}

// ---------------------------------------------------------------- symmetry of the networks

const char* const kSacSpecs[] = {test::kMirrorSpec, test::kC3Spec, test::kC4Spec};

SacPolicyShape smallShape(Method method) {
  SacPolicyShape s;
  s.method = method;
  s.hidden = {16, 12};
  return s;
}

// |T| of a signed permutation map applied to x.
Mat<float> applyUnsigned(const sym::SparseMap& t, const Mat<float>& x) {
  return t.toDense().cwiseAbs().cast<float>() * x;
}

struct PolicySymmetry {
  double mean = 0, log_std = 0, action = 0, log_prob = 0;
};

// max over i, b of the violations of mean(T o) = T mean(o), log_std(T o) = |T| log_std(o), and for
// the sample with noise T eps: a(T o) = T a(o), log pi(T a | T o) = log pi(a | o); through a fitted
// symmetric normalizer.
PolicySymmetry policySymmetry(const sym::SymmetrySpec& spec, Method method) {
  Rng rng(4);
  SacPolicy<float> p(spec, smallShape(method));
  p.initialize(rng, 1.0f);  // a full-size last layer: outputs far from zero
  const int o = spec.obsDim(), a = spec.actDim(), b = 7;
  const Mat<float> fit = 2.0f * Mat<float>::Random(o, 64) + Mat<float>::Constant(o, 64, 0.5f);
  p.obsNormalizer().update(fit);
  p.setNormalizes(true);
  const Mat<float> obs = Mat<float>::Random(o, b);
  Mat<float> eps(a, b), obs_n, act(a, b), lp(1, b), tobs(o, b), teps(a, b), tact(a, b), tlp(1, b);
  squashed_gaussian::drawNoise<float>(rng, eps);
  p.normalize(obs, obs_n);
  p.forward(obs_n);
  const Mat<float> mean = p.mean(), log_std = p.logStd();
  squashed_gaussian::sample<float>(mean, log_std, eps, act, lp);
  PolicySymmetry worst;
  for (int i = 1; i < spec.numAgents(); ++i) {
    spec.obsTransform(i).apply<float>(obs, tobs);
    spec.actTransform(i).apply<float>(eps, teps);
    p.normalize(tobs, obs_n);
    p.forward(obs_n);
    squashed_gaussian::sample<float>(p.mean(), p.logStd(), teps, tact, tlp);
    Mat<float> t_mean(a, b), t_act(a, b);
    spec.actTransform(i).apply<float>(mean, t_mean);
    spec.actTransform(i).apply<float>(act, t_act);
    auto rel = [](const Mat<float>& x, const Mat<float>& ref) {
      return static_cast<double>(((x - ref).array().abs() / (1 + ref.array().abs())).maxCoeff());
    };
    worst.mean = std::max(worst.mean, rel(p.mean(), t_mean));
    worst.log_std = std::max(worst.log_std, rel(p.logStd(), applyUnsigned(spec.actTransform(i), log_std)));
    worst.action = std::max(worst.action, rel(tact, t_act));
    worst.log_prob = std::max(worst.log_prob, rel(tlp, lp));
  }
  return worst;
}

TEST(SacSymmetry, MasaPolicyIsEquivariantInMeanLogStdActionAndLogProbAndSaIsNot) {
  for (const char* yaml : kSacSpecs) {
    const auto spec = test::spec(yaml, "spec");
    const PolicySymmetry masa = policySymmetry(spec, Method::kMasa);
    EXPECT_LT(masa.mean, 1e-5) << spec.name();
    EXPECT_LT(masa.log_std, 1e-5) << spec.name();
    EXPECT_LT(masa.action, 1e-5) << spec.name();
    EXPECT_LT(masa.log_prob, 1e-5) << spec.name();
    const PolicySymmetry sa = policySymmetry(spec, Method::kSa);
    EXPECT_GT(sa.mean, 1e-3) << spec.name();
    EXPECT_GT(sa.log_std, 1e-3) << spec.name();
  }
}

double twinQSymmetry(const sym::SymmetrySpec& spec, Method method) {
  Rng rng(6);
  offline::TwinQ<float> q(spec, twinQMaps(method, spec), {16, 12}, nn::Activation::kElu);
  q.initialize(rng);
  const int o = spec.obsDim(), a = spec.actDim(), b = 9;
  const Mat<float> obs = Mat<float>::Random(o, b), act = Mat<float>::Random(a, b);
  const Mat<float> q0 = q.forward(obs, act);
  Mat<float> tobs(o, b), tact(a, b);
  double worst = 0;
  for (int i = 1; i < spec.numAgents(); ++i) {
    spec.obsTransform(i).apply<float>(obs, tobs);
    spec.actTransform(i).apply<float>(act, tact);
    const Mat<float> qi = q.forward(tobs, tact);
    worst = std::max(worst, static_cast<double>(((qi - q0).array().abs() / (1 + q0.array().abs())).maxCoeff()));
  }
  return worst;
}

TEST(SacSymmetry, MasaTwinQIsInvariantUnderTheJointTransformAndSaAndMaAreNot) {
  for (const char* yaml : kSacSpecs) {
    const auto spec = test::spec(yaml, "spec");
    EXPECT_LT(twinQSymmetry(spec, Method::kMasa), 1e-5) << spec.name();
    EXPECT_GT(twinQSymmetry(spec, Method::kSa), 1e-4) << spec.name();
    EXPECT_GT(twinQSymmetry(spec, Method::kMa), 1e-4) << spec.name();
  }
}

TEST(SacSymmetry, ThePolicyRefusesASpecWhoseActionTransformIsNotASignedPermutation) {
  const auto spec = test::spec(test::kMirrorSpec, "spec");
  auto maps = meanAndLogStdMaps(Method::kMasa, spec);
  EXPECT_EQ(maps.act_dim, 2 * spec.actDim());
  // |Out_i| of every map: the log-std half holds the mean half's entries without signs.
  for (const auto& m : maps.output) {
    const Eigen::MatrixXd d = m.toDense();
    const int a = spec.actDim(), h = maps.agent_output_dim / 2;
    EXPECT_EQ(d.bottomRightCorner(a, h), d.topLeftCorner(a, h).cwiseAbs());
  }
}

// ---------------------------------------------------------------- losses by hand

TEST(SacLosses, SoftTargetAndTwinQLossAreTheHandComputedValues) {
  Mat<double> r(1, 2), disc(1, 2), minq(1, 2), lp(1, 2), y(1, 2), q(2, 2), dq(2, 2);
  r << 1.0, -2.0;
  disc << 0.99, 0.0;  // the second sample terminated
  minq << 3.0, 7.0;
  lp << -1.5, 0.5;
  softQTarget<double>(r, disc, minq, lp, 0.2, y);
  EXPECT_DOUBLE_EQ(y(0), 1.0 + 0.99 * (3.0 + 0.2 * 1.5));  // 4.267
  EXPECT_DOUBLE_EQ(y(1), -2.0);
  q << 4.0, -1.0,
       5.0, -3.0;
  const double loss = twinQLoss<double>(q, y, dq);
  // ((4 - 4.267)^2 + (-1 + 2)^2 + (5 - 4.267)^2 + (-3 + 2)^2) / 2
  EXPECT_NEAR(loss, (0.267 * 0.267 + 1 + 0.733 * 0.733 + 1) / 2, 1e-12);
  EXPECT_NEAR(dq(0, 0), 2 * (4 - 4.267) / 2, 1e-12);
  EXPECT_NEAR(dq(1, 1), 2 * (-3 + 2) / 2, 1e-12);
}

TEST(SacLosses, ActorLossTakesTheSmallerQAndTheTemperatureLossMovesAlphaTowardsTheTargetEntropy) {
  Mat<double> lp(1, 2), q(2, 2), dlp(1, 2), dq(2, 2);
  lp << -1.0, 2.0;
  q << 3.0, 1.0,
       2.0, 4.0;  // min: Q2 for the first sample, Q1 for the second
  const double loss = actorLoss<double>(lp, q, 0.5, dlp, dq);
  EXPECT_DOUBLE_EQ(loss, ((0.5 * -1.0 - 2.0) + (0.5 * 2.0 - 1.0)) / 2);  // -1.25
  EXPECT_DOUBLE_EQ(dq(1, 0), -0.5);
  EXPECT_DOUBLE_EQ(dq(0, 0), 0.0);
  EXPECT_DOUBLE_EQ(dq(0, 1), -0.5);
  EXPECT_DOUBLE_EQ(dq(1, 1), 0.0);
  EXPECT_DOUBLE_EQ(dlp(0), 0.25);

  // alpha = exp(log 0.2); mean log pi = 0.5; target entropy -3: L = -0.2 (0.5 - 3) = 0.5
  double dla = 0;
  const double tl = temperatureLoss<double>(std::log(0.2), lp, -3.0, dla);
  EXPECT_NEAR(tl, 0.5, 1e-12);
  EXPECT_NEAR(dla, 0.5, 1e-12);  // > 0: descent lowers alpha, the entropy (-0.5) is above -3
  EXPECT_NEAR(temperatureLoss<double>(0.0, lp, 1.0, dla), -1.5, 1e-12);
  EXPECT_LT(dla, 0);  // entropy -0.5 below the target 1: descent raises alpha
}

// ---------------------------------------------------------------- gradients through the networks

struct SacFixture {
  sym::SymmetrySpec spec;
  SacPolicy<double> policy;
  offline::TwinQ<double> q, q_target;
  SacConfig config;
  ReplayBatch<double> batch;

  SacFixture(const char* yaml, Method method, uint64_t seed = 11)
      : spec(test::spec(yaml, "spec")),
        policy(spec, smallShape(method)),
        q(spec, twinQMaps(method, spec), {9, 6}, nn::Activation::kElu),
        q_target(spec, twinQMaps(method, spec), {9, 6}, nn::Activation::kElu) {
    Rng rng(seed);
    policy.initialize(rng, 0.5);
    q.initialize(rng);
    q_target.initialize(rng);
    const Mat<double> fit = Mat<double>::Random(spec.obsDim(), 32) * 2.0;
    policy.obsNormalizer().update(fit);
    policy.setNormalizes(true);
    config.init_alpha = 0.3;
    const int b = 5;
    batch.resize(spec.obsDim(), spec.actDim(), b);
    batch.obs.setRandom();
    batch.next_obs.setRandom();
    batch.actions = 0.8 * Mat<double>::Random(spec.actDim(), b);
    batch.rewards.setRandom();
    batch.discount << 0.99, 0.0, 0.9801, 0.99, 0.99;
  }
};

const Method kAllMethods[] = {Method::kMasa, Method::kSa, Method::kSasa, Method::kMa};

TEST(SacGradient, CriticActorAndTemperatureLossesMatchFiniteDifferencesForEveryMethod) {
  for (const char* yaml : {test::kMirrorSpec, test::kC4Spec})
    for (Method method : kAllMethods) {
      SacFixture f(yaml, method);
      SacTrainer<double> trainer(f.policy, f.q, f.q_target, f.config);
      const std::string what = std::string(f.spec.name()) + " " + model::methodName(method);
      // The same noise at every evaluation: a fresh generator of one seed.
      auto critic = [&] { Rng r(7); return static_cast<double>(trainer.criticLoss(f.batch, r)); };
      auto actor = [&] { Rng r(8); return static_cast<double>(trainer.actorLoss(f.batch, r)); };
      critic();
      const Vec<double> gq = f.q.params().grads();
      const auto rq = test::checkGradient(f.q.params().values(), gq, critic);
      EXPECT_GT(gq.norm(), 1e-3) << what;
      EXPECT_LT(rq.max_relative_error, 1e-4) << what << " critic, worst " << rq.worst_index;
      actor();
      const Vec<double> gp = f.policy.params().grads();
      EXPECT_EQ(f.q.params().grads().cwiseAbs().maxCoeff(), 0.0) << what;  // the actor does not train Q
      const auto rp = test::checkGradient(f.policy.params().values(), gp, actor);
      EXPECT_GT(gp.norm(), 1e-3) << what;
      EXPECT_LT(rp.max_relative_error, 1e-4) << what << " actor, worst " << rp.worst_index;
      if (method == Method::kSasa) {
        EXPECT_GT(f.policy.symmetryLoss(), 0.0) << what;
      }
    }
}

TEST(SacGradient, TemperatureGradientMatchesTheFiniteDifferenceOfLogAlpha) {
  Mat<double> lp(1, 3);
  lp << -2.0, 0.4, 1.1;
  const double h = 1e-6, log_alpha = std::log(0.3);
  double d = 0, unused = 0;
  temperatureLoss<double>(log_alpha, lp, -6.0, d);
  const double up = temperatureLoss<double>(log_alpha + h, lp, -6.0, unused);
  const double down = temperatureLoss<double>(log_alpha - h, lp, -6.0, unused);
  EXPECT_NEAR(d, (up - down) / (2 * h), 1e-8);
}

// ---------------------------------------------------------------- steps, resume

TEST(SacTrainerSteps, AStepMovesEveryPartAndTheTargetByPolyak) {
  SacFixture f(test::kMirrorSpec, Method::kMasa);
  f.config.polyak = 0.25;
  f.q_target.moveTowards(f.q, 1.0);
  SacTrainer<double> trainer(f.policy, f.q, f.q_target, f.config);
  const Vec<double> p0 = f.policy.params().values(), q0 = f.q.params().values();
  const double a0 = trainer.alpha();
  Rng rng(1);
  const SacStats s = trainer.step(f.batch, rng);
  EXPECT_GT((f.policy.params().values() - p0).norm(), 0.0);
  EXPECT_GT((f.q.params().values() - q0).norm(), 0.0);
  EXPECT_NE(trainer.alpha(), a0);
  EXPECT_EQ(s.alpha, trainer.alpha());
  // Q' = Q0 + 0.25 (Q1 - Q0)
  EXPECT_LT((f.q_target.params().values() - (q0 + 0.25 * (f.q.params().values() - q0))).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(trainer.steps(), 1);
}

TEST(SacTrainerSteps, AResumedTrainerTakesTheSameNextStepBitForBit) {
  const auto spec = test::spec(test::kC4Spec, "spec");
  auto fill = [&](ReplayBuffer& rb) {
    Rng data(9);
    std::vector<float> o(spec.obsDim()), n(spec.obsDim()), a(spec.actDim());
    std::uniform_real_distribution<float> u(-1, 1);
    for (int k = 0; k < 40; ++k) {
      for (float& x : o) x = u(data);
      for (float& x : n) x = u(data);
      for (float& x : a) x = u(data);
      rb.add(o.data(), a.data(), u(data), n.data(), k % 13 == 12, k % 17 == 16);
    }
  };
  SacConfig config;
  config.n_step = 3;
  struct Run {
    SacPolicy<float> policy;
    offline::TwinQ<float> q, q_target;
    SacTrainer<float> trainer;
    ReplayBuffer rb;
    Rng rng;
    Run(const sym::SymmetrySpec& spec, const SacConfig& c, uint64_t seed)
        : policy(spec, smallShape(Method::kMasa)),
          q(spec, twinQMaps(Method::kMasa, spec), {9, 6}, nn::Activation::kElu),
          q_target(spec, twinQMaps(Method::kMasa, spec), {9, 6}, nn::Activation::kElu),
          trainer(policy, q, q_target, c),
          rb(spec.obsDim(), spec.actDim(), 32),
          rng(seed) {
      policy.initialize(rng);
      q.initialize(rng);
      q_target.moveTowards(q, 1.0f);
    }
    void step(const SacConfig& c) {
      ReplayBatch<float> batch;
      rb.sample(8, c.n_step, c.discount, rng, batch);
      trainer.step(batch, rng);
    }
  };
  Run first(spec, config, 1);
  fill(first.rb);
  first.policy.obsNormalizer().update(Mat<float>::Random(spec.obsDim(), 16));
  first.policy.setNormalizes(true);
  for (int k = 0; k < 3; ++k) first.step(config);
  std::stringstream state;
  first.trainer.save(state);
  first.rb.save(state);
  state << first.rng << '\n';

  Run resumed(spec, config, 2);  // other initial parameters, empty buffer: everything must come from the state
  EXPECT_NE(resumed.policy.params().values(), first.policy.params().values());
  resumed.trainer.load(state);
  resumed.rb.load(state);
  state >> resumed.rng;
  first.step(config);
  resumed.step(config);
  EXPECT_EQ(resumed.trainer.steps(), 4);
  EXPECT_EQ(resumed.policy.params().values(), first.policy.params().values());
  EXPECT_EQ(resumed.q.params().values(), first.q.params().values());
  EXPECT_EQ(resumed.q_target.params().values(), first.q_target.params().values());
  EXPECT_EQ(resumed.trainer.logAlpha(), first.trainer.logAlpha());
}

// A one-step bandit: reward -(a - 0.5)^2 on each action entry, every episode one step. SAC's
// policy mean moves to 0.5 (the entropy bonus keeps some spread, not the mean).
double banditError(const char* yaml, int steps, double lr, double init_alpha, double ent, int width) {
  const auto spec = test::spec(yaml, "spec");
  SacPolicy<float> policy(spec, smallShape(Method::kSa));
  offline::TwinQ<float> q(spec, twinQMaps(Method::kSa, spec), {width, width}, nn::Activation::kElu),
      q_target(spec, twinQMaps(Method::kSa, spec), {width, width}, nn::Activation::kElu);
  SacConfig config;
  config.policy_lr = config.q_lr = lr;
  config.alpha_lr = lr;
  config.init_alpha = init_alpha;
  config.target_entropy_per_dim = ent;
  SacTrainer<float> trainer(policy, q, q_target, config);
  Rng rng(21);
  policy.initialize(rng);
  q.initialize(rng);
  q_target.moveTowards(q, 1.0f);
  ReplayBuffer rb(spec.obsDim(), spec.actDim(), 5000);
  std::vector<float> o(spec.obsDim(), 0.1f), act(spec.actDim());
  ReplayBatch<float> batch;
  Mat<float> best(spec.actDim(), 1);
  for (int t = 0; t < steps; ++t) {
    policy.actStochastic(Eigen::Map<const Mat<float>>(o.data(), spec.obsDim(), 1), rng,
                         Eigen::Map<Mat<float>>(act.data(), spec.actDim(), 1));
    double r = 0;
    for (float a : act) r -= (a - 0.5) * (a - 0.5);
    rb.add(o.data(), act.data(), r, o.data(), true, false);
    rb.sample(64, 1, 0.99, rng, batch);
    trainer.step(batch, rng);
  }
  policy.actDeterministic(Eigen::Map<const Mat<float>>(o.data(), spec.obsDim(), 1), best);
  return (best.array() - 0.5f).abs().maxCoeff();
}

TEST(SacTrainerSteps, LearnsTheBestActionOfABandit) {
  // 3000 steps at Adam 3e-3 with the default target entropy: within 0.05 here (0.44 at 1000 steps).
  EXPECT_LT(banditError(test::kMirrorSpec, 3000, 3e-3, 0.1, -1.0, 32), 0.1);
}

// ---------------------------------------------------------------- config

TEST(SacConfigTest, DefaultsReadAndUnknownOrBadKeysAreErrorsNamingTheKey) {
  const std::string configs = std::string(MASA_SOURCE_DIR) + "/configs";
  const SacConfig c = readSacConfig(config::loadRunConfig(configs, {"task=a1_beam", "sac.n_step=3"}));
  EXPECT_EQ(c.n_step, 3);
  EXPECT_EQ(c.batch_size, 256);
  EXPECT_DOUBLE_EQ(c.target_entropy_per_dim, -1.0);
  EXPECT_THROW(config::loadRunConfig(configs, {"task=a1_beam", "sac.nstep=3"}), ConfigError);
  // Checkpoints are taken at metrics rows only.
  EXPECT_THROW(readSacConfig(config::loadRunConfig(configs, {"task=a1_beam", "sac.checkpoint_every=1500"})), ConfigError);
  try {
    readSacConfig(config::loadRunConfig(configs, {"task=a1_beam", "sac.polyak=0"}));
    FAIL() << "polyak 0 accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("sac.polyak"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("command line"), std::string::npos) << e.what();
  }
}

// Before the shared reader (common/core/config_section.hpp) a sac number without a range took
// NaN and positive() took infinity.
TEST(SacConfigTest, NaNOrInfinityIsRefusedNamingTheKeyPath) {
  const std::string configs = std::string(MASA_SOURCE_DIR) + "/configs";
  for (const std::string set : {"sac.target_entropy_per_dim=.nan", "sac.policy_lr=.inf", "sac.init_alpha=.inf",
                                "sac.log_std_min=-.inf", "sac.q_lr=.nan"}) {
    const ConfigError e = test::configErrorOf([&] { readSacConfig(config::loadRunConfig(configs, {"task=a1_beam", set})); });
    EXPECT_EQ(e.key(), set.substr(0, set.find('='))) << set << ": " << e.what();
    EXPECT_EQ(e.file(), "command line") << e.what();
  }
}

}  // namespace
}  // namespace masa::sac
