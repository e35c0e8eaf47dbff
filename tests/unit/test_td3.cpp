// TD3 on the SAC policy network (learner/sac/td3_trainer.hpp): the noisy actions against hand
// values (the smoothing noise clipped, the action clipped to [-1, 1]); MASA's noisy actions
// equivariant (noise T eps) and its actor loss invariant to 1e-5 in float, where SA fails; the
// critic and actor losses' gradients against central differences in double for the four methods;
// the critic's loss recomputed by hand from the smoothed target policy and the target Qs;
// the delayed actor (policy and both targets still for td3_policy_delay - 1 steps, then the targets
// moved by exactly Polyak); a resumed trainer taking the same next step bit for bit; a bandit
// learned; the sac.algorithm and sac.td3_* keys read strictly.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <sstream>

#include "common/config/run_config.hpp"
#include "common/core/config_error.hpp"
#include "learner/sac/replay_buffer.hpp"
#include "learner/sac/sac_critic_maps.hpp"
#include "common/model/squashed_gaussian.hpp"
#include "common/model/td3_noise.hpp"
#include "learner/sac/td3_trainer.hpp"
#include "model_test_support.hpp"

namespace masa::sac {
namespace {

using model::Method;

const Method kTd3Methods[] = {Method::kMasa, Method::kSa, Method::kSasa, Method::kMa};

SacPolicyShape smallTd3Shape(Method method) {
  SacPolicyShape s;
  s.method = method;
  s.hidden = {16, 12};
  return s;
}

TEST(Td3Noise, TheSmoothingNoiseAndTheActionAreClipped) {
  Mat<double> mean(4, 1), eps(4, 1), out(4, 1);
  mean << std::atanh(0.5), std::atanh(0.5), std::atanh(0.9), std::atanh(-0.2);
  eps << 1.0, 5.0, 0.8, -10.0;
  td3::noisyActions<double>(mean, eps, 0.2, 0.5, out);
  EXPECT_NEAR(out(0), 0.5 + 0.2, 1e-12);   // within both clips
  EXPECT_NEAR(out(1), 0.5 + 0.5, 1e-12);   // noise 1.0 clipped to 0.5
  EXPECT_NEAR(out(2), 1.0, 1e-12);         // 0.9 + 0.16 clipped to the action bound
  EXPECT_NEAR(out(3), -0.2 - 0.5, 1e-12);  // noise -2 clipped to -0.5
  // Collection: no clip on the noise, only on the action.
  td3::noisyActions<double>(mean, eps, 0.2, std::numeric_limits<double>::infinity(), out);
  EXPECT_NEAR(out(1), 1.0, 1e-12);
  EXPECT_NEAR(out(3), -1.0, 1e-12);
  eps.setZero();
  td3::noisyActions<double>(mean, eps, 0.2, 0.5, out);
  EXPECT_LT((out - mean.array().tanh().matrix()).cwiseAbs().maxCoeff(), 1e-15);  // no noise: tanh(mean)
}

// max over i, b of the violations of a(T o, T eps) = T a(o, eps) for the target-smoothing noise.
double noisyActionSymmetry(const sym::SymmetrySpec& spec, Method method) {
  Rng rng(4);
  SacPolicy<float> p(spec, smallTd3Shape(method));
  p.initialize(rng, 1.0f);
  const int o = spec.obsDim(), a = spec.actDim(), b = 7;
  Mat<float> obs(o, b), eps(a, b), act(a, b), tobs(o, b), teps(a, b), tact(a, b), want(a, b);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  for (float& x : obs.reshaped()) x = u(rng);
  squashed_gaussian::drawNoise<float>(rng, eps);
  p.forward(obs);
  td3::noisyActions<float>(p.mean(), eps, 0.4f, 0.5f, act);
  double worst = 0;
  for (int i = 1; i < spec.numAgents(); ++i) {
    spec.obsTransform(i).apply<float>(obs, tobs);
    spec.actTransform(i).apply<float>(eps, teps);
    p.forward(tobs);
    td3::noisyActions<float>(p.mean(), teps, 0.4f, 0.5f, tact);
    spec.actTransform(i).apply<float>(act, want);
    worst = std::max(worst, static_cast<double>(((tact - want).array().abs() / (1 + want.array().abs())).maxCoeff()));
  }
  return worst;
}

TEST(Td3Symmetry, MasaNoisyActionsAreEquivariantAndSaIsNot) {
  for (const char* yaml : {test::kMirrorSpec, test::kC3Spec, test::kC4Spec}) {
    const auto spec = test::spec(yaml, "spec");
    EXPECT_LT(noisyActionSymmetry(spec, Method::kMasa), 1e-5) << spec.name();
    EXPECT_GT(noisyActionSymmetry(spec, Method::kSa), 1e-3) << spec.name();
  }
}

template <typename S>
struct Td3Fixture {
  sym::SymmetrySpec spec;
  SacPolicy<S> policy;
  offline::TwinQ<S> q, q_target;
  SacConfig config;
  ReplayBatch<S> batch;

  Td3Fixture(const char* yaml, Method method, uint64_t seed = 11)
      : spec(test::spec(yaml, "spec")),
        policy(spec, smallTd3Shape(method)),
        q(spec, twinQMaps(method, spec), {9, 6}, nn::Activation::kElu),
        q_target(spec, twinQMaps(method, spec), {9, 6}, nn::Activation::kElu) {
    Rng rng(seed);
    policy.initialize(rng, S(0.5));
    q.initialize(rng);
    q_target.initialize(rng);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Mat<S> fit(spec.obsDim(), 32);
    for (S& x : fit.reshaped()) x = static_cast<S>(2 * u(rng));
    policy.obsNormalizer().update(fit);
    policy.setNormalizes(true);
    const int b = 5;
    batch.resize(spec.obsDim(), spec.actDim(), b);
    for (S& x : batch.obs.reshaped()) x = static_cast<S>(u(rng));
    for (S& x : batch.next_obs.reshaped()) x = static_cast<S>(u(rng));
    for (S& x : batch.actions.reshaped()) x = static_cast<S>(0.8 * u(rng));
    for (S& x : batch.rewards.reshaped()) x = static_cast<S>(u(rng));
    batch.discount << S(0.99), S(0), S(0.9801), S(0.99), S(0.99);
  }
};

// The actor loss -mean Q_1(o, tanh(mean(o))) on the batch and on its transform T_i o.
double actorLossSymmetry(const char* yaml, Method method) {
  Td3Fixture<float> f(yaml, method);
  Td3Trainer<float> trainer(f.spec, f.policy, f.q, f.q_target, f.config);
  const double l0 = trainer.actorLoss(f.batch);
  double worst = 0;
  ReplayBatch<float> t = f.batch;
  for (int i = 1; i < f.spec.numAgents(); ++i) {
    f.spec.obsTransform(i).apply<float>(f.batch.obs, t.obs);
    worst = std::max(worst, std::abs(trainer.actorLoss(t) - l0) / (1 + std::abs(l0)));
  }
  return worst;
}

TEST(Td3Symmetry, MasaActorLossIsInvariantAndSaIsNot) {
  for (const char* yaml : {test::kMirrorSpec, test::kC4Spec}) {
    EXPECT_LT(actorLossSymmetry(yaml, Method::kMasa), 1e-5) << yaml;
    EXPECT_GT(actorLossSymmetry(yaml, Method::kSa), 1e-4) << yaml;
  }
}

TEST(Td3Gradient, CriticAndActorLossesMatchFiniteDifferencesForEveryMethod) {
  for (const char* yaml : {test::kMirrorSpec, test::kC4Spec})
    for (Method method : kTd3Methods) {
      Td3Fixture<double> f(yaml, method);
      Td3Trainer<double> trainer(f.spec, f.policy, f.q, f.q_target, f.config);
      const std::string what = std::string(f.spec.name()) + " " + model::methodName(method);
      auto critic = [&] { Rng r(7); return static_cast<double>(trainer.criticLoss(f.batch, r)); };
      auto actor = [&] { return static_cast<double>(trainer.actorLoss(f.batch)); };
      f.policy.params().zeroGrad();
      critic();
      EXPECT_EQ(f.policy.params().grads().cwiseAbs().maxCoeff(), 0.0) << what;  // the critic does not train the policy
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
    }
}

// The critic's target from the target policy (not the online one, moved away here), smoothed with
// the generator's noise, and the target Qs' minimum: the loss recomputed by hand.
TEST(Td3TrainerSteps, TheCriticTargetIsTheSmoothedTargetPolicyThroughTheTargetQsMinimum) {
  Td3Fixture<double> f(test::kC4Spec, Method::kMasa);
  Td3Trainer<double> trainer(f.spec, f.policy, f.q, f.q_target, f.config);
  const Vec<double> target_params = f.policy.params().values();
  f.policy.params().values() *= 1.7;  // the online policy is no longer the target
  Rng r(5), expect(5);
  const double loss = trainer.criticLoss(f.batch, r);
  SacPolicy<double> target(f.spec, smallTd3Shape(Method::kMasa));
  target.params().values() = target_params;
  const int a = f.spec.actDim(), b = f.batch.size();
  Mat<double> next_n, eps(a, b), act(a, b), min_q(1, b), obs_n, dq(2, b);
  f.policy.normalize(f.batch.next_obs, next_n);
  target.forward(next_n);
  squashed_gaussian::drawNoise<double>(expect, eps);
  td3::noisyActions<double>(target.mean(), eps, f.config.td3_policy_noise, f.config.td3_noise_clip, act);
  f.q_target.minQ(next_n, act, min_q);
  const Mat<double> y = f.batch.rewards + f.batch.discount.cwiseProduct(min_q);
  f.policy.normalize(f.batch.obs, obs_n);
  const Mat<double> q = f.q.forward(obs_n, f.batch.actions);
  const double want = (q.rowwise() - y.row(0)).squaredNorm() / b;
  EXPECT_NEAR(loss, want, 1e-12 * (1 + want));
  // With the online policy in place of the target the loss would differ.
  f.policy.forward(next_n);
  td3::noisyActions<double>(f.policy.mean(), eps, f.config.td3_policy_noise, f.config.td3_noise_clip, act);
  f.q_target.minQ(next_n, act, min_q);
  const Mat<double> y_online = f.batch.rewards + f.batch.discount.cwiseProduct(min_q);
  EXPECT_GT(std::abs((q.rowwise() - y_online.row(0)).squaredNorm() / b - want), 1e-6);
}

TEST(Td3TrainerSteps, TheActorAndBothTargetsMoveEveryPolicyDelayStepsTheTargetsByPolyak) {
  Td3Fixture<double> f(test::kMirrorSpec, Method::kMasa);
  f.config.polyak = 0.25;
  f.config.td3_policy_delay = 3;
  f.q_target.moveTowards(f.q, 1.0);
  Td3Trainer<double> trainer(f.spec, f.policy, f.q, f.q_target, f.config);
  const Vec<double> p0 = f.policy.params().values(), qt0 = f.q_target.params().values();
  EXPECT_EQ(trainer.targetPolicy().params().values(), p0);
  Rng rng(1);
  for (int k = 1; k <= 2; ++k) {
    Vec<double> q_before = f.q.params().values();
    trainer.step(f.batch, rng);
    EXPECT_GT((f.q.params().values() - q_before).norm(), 0.0) << k;
    EXPECT_EQ(f.policy.params().values(), p0) << k;
    EXPECT_EQ(f.q_target.params().values(), qt0) << k;
    EXPECT_EQ(trainer.targetPolicy().params().values(), p0) << k;
  }
  trainer.step(f.batch, rng);
  EXPECT_EQ(trainer.steps(), 3);
  EXPECT_GT((f.policy.params().values() - p0).norm(), 0.0);
  EXPECT_LT((f.q_target.params().values() - (qt0 + 0.25 * (f.q.params().values() - qt0))).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((trainer.targetPolicy().params().values() - (p0 + 0.25 * (f.policy.params().values() - p0)))
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
}

TEST(Td3TrainerSteps, AResumedTrainerTakesTheSameNextStepBitForBit) {
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
    Td3Trainer<float> trainer;
    ReplayBuffer rb;
    Rng rng;
    Run(const sym::SymmetrySpec& spec, const SacConfig& c, uint64_t seed)
        : policy(spec, smallTd3Shape(Method::kMasa)),
          q(spec, twinQMaps(Method::kMasa, spec), {9, 6}, nn::Activation::kElu),
          q_target(spec, twinQMaps(Method::kMasa, spec), {9, 6}, nn::Activation::kElu),
          trainer(spec, policy, q, q_target, c),
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
  for (int k = 0; k < 3; ++k) first.step(config);  // odd: the next step is an actor step
  std::stringstream state;
  first.trainer.save(state);
  first.rb.save(state);
  state << first.rng << '\n';

  Run resumed(spec, config, 2);
  EXPECT_NE(resumed.policy.params().values(), first.policy.params().values());
  resumed.trainer.load(state);
  resumed.rb.load(state);
  state >> resumed.rng;
  first.step(config);
  resumed.step(config);
  EXPECT_EQ(resumed.trainer.steps(), 4);
  EXPECT_EQ(resumed.policy.params().values(), first.policy.params().values());
  EXPECT_EQ(resumed.trainer.targetPolicy().params().values(), first.trainer.targetPolicy().params().values());
  EXPECT_EQ(resumed.q.params().values(), first.q.params().values());
  EXPECT_EQ(resumed.q_target.params().values(), first.q_target.params().values());
}

// A one-step bandit: reward -(a - 0.5)^2 on each action entry. TD3's tanh(mean) moves to 0.5.
TEST(Td3TrainerSteps, LearnsTheBestActionOfABandit) {
  const auto spec = test::spec(test::kMirrorSpec, "spec");
  SacPolicy<float> policy(spec, smallTd3Shape(Method::kSa));
  offline::TwinQ<float> q(spec, twinQMaps(Method::kSa, spec), {32, 32}, nn::Activation::kElu),
      q_target(spec, twinQMaps(Method::kSa, spec), {32, 32}, nn::Activation::kElu);
  SacConfig config;
  config.policy_lr = config.q_lr = 3e-3;
  config.td3_exploration_noise = 0.3;
  Td3Trainer<float> trainer(spec, policy, q, q_target, config);
  Rng rng(21);
  policy.initialize(rng);
  q.initialize(rng);
  q_target.moveTowards(q, 1.0f);
  ReplayBuffer rb(spec.obsDim(), spec.actDim(), 5000);
  std::vector<float> o(spec.obsDim(), 0.1f), act(spec.actDim());
  ReplayBatch<float> batch;
  Mat<float> best(spec.actDim(), 1);
  for (int t = 0; t < 5000; ++t) {
    trainer.explore(Eigen::Map<const Mat<float>>(o.data(), spec.obsDim(), 1), rng,
                    Eigen::Map<Mat<float>>(act.data(), spec.actDim(), 1));
    double r = 0;
    for (float a : act) r -= (a - 0.5) * (a - 0.5);
    rb.add(o.data(), act.data(), r, o.data(), true, false);
    rb.sample(64, 1, 0.99, rng, batch);
    trainer.step(batch, rng);
  }
  policy.actDeterministic(Eigen::Map<const Mat<float>>(o.data(), spec.obsDim(), 1), best);
  EXPECT_LT((best.array() - 0.5f).abs().maxCoeff(), 0.1f);
}

TEST(Td3Config, TheAlgorithmAndTd3KeysAreReadAndAnUnknownAlgorithmNamesTheKey) {
  const std::string configs = std::string(MASA_SOURCE_DIR) + "/configs";
  const SacConfig d = readSacConfig(config::loadRunConfig(configs, {"task=a1_beam"}));
  EXPECT_EQ(d.algorithm, "sac");
  EXPECT_EQ(d.td3_policy_delay, 2);
  EXPECT_DOUBLE_EQ(d.td3_noise_clip, 0.5);
  const SacConfig c = readSacConfig(
      config::loadRunConfig(configs, {"task=a1_beam", "sac.algorithm=td3", "sac.td3_policy_delay=3"}));
  EXPECT_EQ(c.algorithm, "td3");
  EXPECT_EQ(c.td3_policy_delay, 3);
  try {
    readSacConfig(config::loadRunConfig(configs, {"task=a1_beam", "sac.algorithm=ddpg"}));
    FAIL() << "algorithm ddpg accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("sac.algorithm"), std::string::npos) << e.what();
  }
  EXPECT_THROW(readSacConfig(config::loadRunConfig(configs, {"task=a1_beam", "sac.td3_policy_delay=0"})), ConfigError);
}

}  // namespace
}  // namespace masa::sac
