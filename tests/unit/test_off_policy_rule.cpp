// learner: off_policy (learner/sac/off_policy_rule.hpp, actors/squashed_behaviour.hpp): a round's
// batch joins the replay buffer environment by environment, cut at its end, time-outs bootstrapping
// from their own pre-reset observation and terminations not at all; the gradient steps are
// floor(updates_per_step x transitions past learning_starts); the parameters go out without a
// normalizer while warming up (the actors then act uniformly) and with the very floats the learner
// uses after; an actor acting with them has the learner's mean; a saved and reloaded state takes
// the same next round bit for bit.
#include <gtest/gtest.h>

#include <sstream>

#include "actors/squashed_behaviour.hpp"
#include "common/config/run_config.hpp"
#include "learner/sac/off_policy_rule.hpp"
#include "learner/update_report.hpp"

namespace masa::sac {
namespace {

config::RunConfig smallRun(std::vector<std::string> extra = {}) {
  std::vector<std::string> sets = {"task=a1_beam", "learner=off_policy", "sac.batch_size=4", "sac.policy_hidden=[8]",
                                   "sac.q_hidden=[8]", "sac.n_step=3", "sac.discount=0.5"};
  sets.insert(sets.end(), extra.begin(), extra.end());
  return config::loadRunConfig(std::string(MASA_SOURCE_DIR) + "/configs", sets);
}

// E environments x T steps; observation entry k of (t, e) is 100 e + t + k / 1000, the reward
// 10 e + t, the action 0.1 (t + e).
rollout::Rollout batchOf(int E, int T, int obs_dim, int act_dim) {
  rollout::Rollout b;
  b.allocate(E, T, obs_dim, act_dim);
  for (int t = 0; t <= T; ++t)
    for (int e = 0; e < E; ++e)
      for (int k = 0; k < obs_dim; ++k) b.obsAt(t, e)[k] = 100.0f * e + t + k / 1000.0f;
  for (int t = 0; t < T; ++t)
    for (int e = 0; e < E; ++e) {
      b.reward[b.step(t, e)] = 10.0f * e + t;
      for (int k = 0; k < act_dim; ++k) b.actionAt(t, e)[k] = 0.1f * (t + e);
    }
  return b;
}

TEST(OffPolicyRule, ABatchJoinsReplayEnvironmentByEnvironmentCutAtItsEndTimeOutsFromTheirOwnObservation) {
  const auto rc = smallRun({"sac.learning_starts=1000"});
  Rng rng(1);
  OffPolicyRule rule(rc, rng);
  const int od = rule.replay().obsDim(), ad = rule.replay().actDim();
  auto b = batchOf(2, 3, od, ad);
  b.terminated[b.step(0, 0)] = 1;  // env 0 ends at t = 0 by a fall
  b.truncated[b.step(1, 1)] = 1;   // env 1 is cut by the time limit at t = 1
  std::vector<float> final_obs(od, 777.0f);
  b.addFinal(1, 1, final_obs.data());
  rule.learn(b, {}, rng);
  EXPECT_EQ(rule.roundGradientSteps(), 0);  // warming up: 6 of 1000 transitions
  ASSERT_EQ(rule.replay().size(), 6);
  EXPECT_EQ(rule.gradientSteps(), 0);

  // Stored order: env 0's t = 0, 1, 2, then env 1's: age 5 is env 0's t = 0, age 0 env 1's t = 2.
  ReplayBatch<double> nb;
  nb.resize(od, ad, 4);
  rule.replay().nStep(rule.replay().slotOfAge(5), 3, 0.5, nb, 0);  // env 0, t = 0: the fall
  rule.replay().nStep(rule.replay().slotOfAge(4), 3, 0.5, nb, 1);  // env 0, t = 1: cut after t = 2
  rule.replay().nStep(rule.replay().slotOfAge(2), 3, 0.5, nb, 2);  // env 1, t = 0: time-out at t = 1
  rule.replay().nStep(rule.replay().slotOfAge(0), 3, 0.5, nb, 3);  // env 1, t = 2: the last, cut
  EXPECT_DOUBLE_EQ(nb.rewards(0, 0), 0.0);
  EXPECT_DOUBLE_EQ(nb.discount(0, 0), 0.0);
  EXPECT_DOUBLE_EQ(nb.obs(0, 1), 1.0);                 // t = 1 of env 0
  EXPECT_DOUBLE_EQ(nb.rewards(0, 1), 1.0 + 0.5 * 2.0);  // r1 + g r2, then the stretch ends
  EXPECT_DOUBLE_EQ(nb.discount(0, 1), 0.25);
  EXPECT_NEAR(nb.next_obs(0, 1), 3.0, 1e-6);            // env 0's observation at T, not env 1's
  EXPECT_DOUBLE_EQ(nb.rewards(0, 2), 10.0 + 0.5 * 11.0);
  EXPECT_DOUBLE_EQ(nb.discount(0, 2), 0.25);
  EXPECT_DOUBLE_EQ(nb.next_obs(0, 2), 777.0);           // the time-out's own observation
  EXPECT_DOUBLE_EQ(nb.rewards(0, 3), 12.0);
  EXPECT_DOUBLE_EQ(nb.discount(0, 3), 0.5);
  EXPECT_NEAR(nb.next_obs(0, 3), 103.0, 1e-5);
}

TEST(OffPolicyRule, WarmsUpThenTakesTheStepsOwedAndSendsTheNormalizerItUses) {
  const auto rc = smallRun({"sac.learning_starts=8", "sac.updates_per_step=0.5"});
  Rng rng(2);
  OffPolicyRule rule(rc, rng);
  const int od = rule.replay().obsDim(), ad = rule.replay().actDim();
  const auto b = batchOf(2, 3, od, ad);
  masa::lcmt_policy_params m;
  rule.learn(b, {}, rng);
  EXPECT_EQ(rule.roundGradientSteps(), 0);  // 6 < 8
  rule.fillPolicyMessage(m);
  EXPECT_EQ(m.obs_dim, 0) << "while warming up the parameters go without a normalizer";
  EXPECT_EQ(m.num_params, static_cast<int>(rule.policy().params().size()));
  // 12 transitions: floor(0.5 x (12 - 8 + 1)) = 2 steps; 18: floor(0.5 x 11) = 5, 3 more.
  rule.learn(b, {}, rng);
  EXPECT_EQ(rule.roundGradientSteps(), 2);
  rule.learn(b, {}, rng);
  EXPECT_EQ(rule.roundGradientSteps(), 3);
  EXPECT_EQ(rule.gradientSteps(), 5);
  rule.fillPolicyMessage(m);
  ASSERT_EQ(m.obs_dim, od);

  // An actor acting with the message: its pre-squash mean is the learner's, exactly.
  actor::SquashedBehaviour actor(rc, sym::SymmetrySpec::load(rc.spec_path));
  actor.set(m.params.data(), m.num_params, m.obs_mean.data(), m.obs_std.data());
  ASSERT_FALSE(actor.warmingUp());
  Mat<float> obs = Mat<float>::Random(od, 3), act(ad, 3), mean(ad, 3), on;
  std::vector<Rng> rngs{Rng(1), Rng(2), Rng(3)};
  float logp[3];
  actor.act(obs, rngs, act, mean, logp);
  rule.policy().normalize(obs, on);
  rule.policy().forward(on);
  EXPECT_EQ((mean - Mat<float>(rule.policy().mean())).cwiseAbs().maxCoeff(), 0.0f);
  EXPECT_LT(act.cwiseAbs().maxCoeff(), 1.0f);
  for (float l : logp) EXPECT_TRUE(std::isfinite(l));
}

// sac.checkpoint_replay: the state keeps the newest transitions only; the resumed rule refills to
// learning_starts, taking no gradient steps and owing none for the wait, then goes on at its rate.
TEST(OffPolicyRule, ACompactStateKeepsTheNewestTransitionsAndTheResumedRunRefillsBeforeItStepsAgain) {
  const auto rc = smallRun({"sac.learning_starts=12", "sac.updates_per_step=0.5", "sac.checkpoint_replay=2"});
  Rng rng(2);
  OffPolicyRule rule(rc, rng);
  const auto b = batchOf(2, 3, rule.replay().obsDim(), rule.replay().actDim());
  for (int k = 0; k < 4; ++k) rule.learn(b, {}, rng);  // 24 transitions: floor(0.5 x 13) = 6 steps
  ASSERT_EQ(rule.gradientSteps(), 6);
  std::stringstream state;
  rule.save(state);
  Rng other(7);
  OffPolicyRule back(rc, other);
  back.load(state, "state");
  ASSERT_EQ(back.replay().size(), 2);
  for (long long age = 0; age < 2; ++age) {  // the newest two, in order
    const float* kept = back.replay().obsAt(back.replay().slotOfAge(age));
    const float* was = rule.replay().obsAt(rule.replay().slotOfAge(age));
    EXPECT_TRUE(std::equal(kept, kept + back.replay().obsDim(), was)) << "age " << age;
  }
  EXPECT_EQ(back.gradientSteps(), 6);
  // 2 + 6 = 8 stored, below 12: refilling, no steps (3 were owed for these transitions).
  back.learn(b, {}, other);
  EXPECT_EQ(back.roundGradientSteps(), 0);
  EXPECT_EQ(back.roundFigures()[3].second, 2.0) << back.roundFigures()[3].first;  // warming_up: refilling
  EXPECT_EQ(sac::offPolicyProgressFigures(back.roundFigures()), "refilling the replay after a compact resume: 8 transitions");
  // 14 stored: the round's own 3 steps, none for the wait.
  back.learn(b, {}, other);
  EXPECT_EQ(back.roundGradientSteps(), 3);
  EXPECT_EQ(back.gradientSteps(), 9);
  // The forgiven steps travel in the (compact) state too.
  std::stringstream again;
  back.save(again);
  Rng third(8);
  OffPolicyRule later(rc, third);
  later.load(again, "state");
  for (int k = 0; k < 2; ++k) later.learn(b, {}, third);  // 2 + 12 = 14 >= 12 after the second
  EXPECT_EQ(later.gradientSteps(), 12);  // 9, then forgiven while refilling, then the round's 3
}

TEST(OffPolicyRule, AnActorWarmingUpActsUniformlyAndEachEnvironmentFromItsOwnGenerator) {
  const auto rc = smallRun();
  const auto spec = sym::SymmetrySpec::load(rc.spec_path);
  actor::SquashedBehaviour actor(rc, spec);
  Rng init(3);
  actor.initialize(init);
  EXPECT_TRUE(actor.warmingUp());
  const int od = spec.obsDim(), ad = spec.actDim();
  Mat<float> obs = Mat<float>::Zero(od, 2), act(ad, 2), mean(ad, 2), one(ad, 1), one_mean(ad, 1);
  std::vector<Rng> rngs{Rng(5), Rng(6)}, second{Rng(6)};
  float logp[2];
  actor.act(obs, rngs, act, mean, logp);
  EXPECT_LE(act.cwiseAbs().maxCoeff(), 1.0f);
  EXPECT_GT((act.col(0) - act.col(1)).cwiseAbs().maxCoeff(), 0.0f);
  EXPECT_EQ(mean.cwiseAbs().maxCoeff(), 0.0f);
  actor.act(obs.col(1), second, one, one_mean, logp);  // environment 1 alone, the same generator
  EXPECT_EQ((one - act.col(1)).cwiseAbs().maxCoeff(), 0.0f);
}

TEST(OffPolicyRule, ASavedAndReloadedStateTakesTheSameNextRoundBitForBit) {
  const auto rc = smallRun({"sac.learning_starts=8"});
  Rng rng_a(4), rng_b(99);
  OffPolicyRule a(rc, rng_a), b(rc, rng_b);  // b starts elsewhere: everything must come from the file
  const auto batch = batchOf(2, 3, a.replay().obsDim(), a.replay().actDim());
  a.learn(batch, {}, rng_a);
  a.learn(batch, {}, rng_a);
  std::stringstream state;
  a.save(state);
  b.load(state, "state");
  Rng rng_copy = rng_a;
  a.learn(batch, {}, rng_a);
  b.learn(batch, {}, rng_copy);
  EXPECT_EQ(a.gradientSteps(), b.gradientSteps());
  EXPECT_EQ(a.policy().params().values(), b.policy().params().values());
  masa::lcmt_policy_params ma, mb;
  a.fillPolicyMessage(ma);
  b.fillPolicyMessage(mb);
  EXPECT_EQ(ma.obs_mean, mb.obs_mean);
  EXPECT_EQ(ma.obs_std, mb.obs_std);
  std::stringstream cut(state.str().substr(0, 40));
  EXPECT_THROW(b.load(cut, "cut"), std::runtime_error);
}

}  // namespace
}  // namespace masa::sac

namespace masa::sac {
namespace {

// The progress line of an off-policy round shows its own figures, by the names the rule reports
// (a renamed column would print "nan"), not PPO's kl and lr (always 0 here); a TD3 round has no
// temperature to show.
TEST(OffPolicyRule, TheProgressLineShowsTheRoundsGradientStepsTemperatureAndEntropy) {
  for (const char* algorithm : {"sac", "td3"}) {
    const auto rc = smallRun({"sac.learning_starts=8", std::string("sac.algorithm=") + algorithm});
    Rng rng(4);
    OffPolicyRule rule(rc, rng);
    const auto b = batchOf(2, 3, rule.replay().obsDim(), rule.replay().actDim());
    rule.learn(b, {}, rng);
    EXPECT_EQ(sac::offPolicyProgressFigures(rule.roundFigures()), "warming up: uniform random actions, replay 6");
    rule.learn(b, {}, rng);  // floor(1 x (12 - 8 + 1)) = 5 steps
    const std::string line = sac::offPolicyProgressFigures(rule.roundFigures());
    EXPECT_EQ(line.rfind("grad steps 5  q ", 0), 0u) << line;
    EXPECT_EQ(line.find("nan"), std::string::npos) << line;
    EXPECT_NE(line.find("mean Q "), std::string::npos) << line;
    EXPECT_EQ(line.find("alpha ") != std::string::npos, std::string(algorithm) == "sac") << line;
    EXPECT_EQ(line.find("entropy ") != std::string::npos, std::string(algorithm) == "sac") << line;
  }
}

}  // namespace
}  // namespace masa::sac
