// Learning smoke check without LCM or MuJoCo: a mirror-symmetric contextual bandit with time-outs,
// rolled out in-process with the policy, trained by PPO as MASA and as SA.
#include <gtest/gtest.h>

#include <memory>

#include "common/model/diag_gaussian.hpp"
#include "learner/ppo/ppo_trainer.hpp"

namespace masa::ppo {
namespace {

// Observation [c, g, target_0, target_1], action [a_c, a_0, a_1]. The mirror flips c and a_c and
// swaps the two limbs, so the best action a* = (c, (target_0 + g) / 2, (target_1 + g) / 2) is
// equivariant and both MASA and SA can represent it.
const char* kBanditSpec = R"(
name: mirror_bandit
group: {type: reflection, axis: y}
observation:
  central:
    - {name: c, kind: odd}
    - {name: g, kind: invariant}
  limb:
    - {name: target, kind: invariant}
action:
  central:
    - {name: a_c, kind: odd}
  limb:
    - {name: a_limb, kind: invariant}
)";

constexpr int kEpisodeLength = 4;  // then a time-out

// reward = -||a - a*(o)||^2; each step shows a fresh random observation.
class MirrorBandit {
 public:
  MirrorBandit(int num_envs, Rng& rng) : obs_(4, num_envs), steps_(num_envs, 0) {
    for (int e = 0; e < num_envs; ++e) draw(obs_.col(e), rng);
  }
  const Mat<float>& obs() const { return obs_; }

  // Steps every env; writes rewards and time-outs of row t into the buffer.
  void step(const Eigen::Ref<const Mat<float>>& actions, int t, RolloutBuffer& buffer, Rng& rng) {
    Vec<float> next(4);
    for (int e = 0; e < obs_.cols(); ++e) {
      const auto o = obs_.col(e);
      const float best[3] = {o(0), 0.5f * (o(2) + o(1)), 0.5f * (o(3) + o(1))};
      float r = 0;
      for (int d = 0; d < 3; ++d) r -= (actions(d, e) - best[d]) * (actions(d, e) - best[d]);
      buffer.rewards()(t, e) = r;
      buffer.terminated()(t, e) = 0;
      draw(next, rng);
      const bool time_out = ++steps_[e] == kEpisodeLength;
      buffer.truncated()(t, e) = time_out ? 1 : 0;
      if (time_out) {
        buffer.addFinalObs(t, e, next);  // where the episode would have gone on
        steps_[e] = 0;
        draw(next, rng);  // the reset
      }
      obs_.col(e) = next;
    }
  }

 private:
  template <typename Col>
  static void draw(Col&& col, Rng& rng) {
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    for (int d = 0; d < 4; ++d) col(d) = u(rng);
  }
  Mat<float> obs_;
  std::vector<int> steps_;
};

// Fills the buffer with one batch from the current policy; returns the mean reward per step.
double collect(model::ActorCritic<float>& model, MirrorBandit& env, RolloutBuffer& buffer, Rng& rng) {
  buffer.clear();
  const int E = buffer.numEnvs();
  Vec<float> log_std(buffer.actDim());
  model.logStd(log_std);
  buffer.envLogStds().colwise() = log_std;
  for (int t = 0; t < buffer.horizon(); ++t) {
    auto obs = buffer.obs().middleCols(t * E, E);
    auto means = buffer.means().middleCols(t * E, E);
    auto actions = buffer.actions().middleCols(t * E, E);
    obs = env.obs();
    means = model.actMean(obs);
    model::gaussian::sample<float>(means, log_std, rng, actions);
    model::gaussian::logProb<float>(means, log_std, actions, buffer.logProbs().middleCols(t * E, E));
    env.step(actions, t, buffer, rng);
  }
  buffer.bootstrapObs() = env.obs();
  return buffer.rewards().mean();
}

struct Curve {
  double initial = 0, final = 0;
};

Curve train(model::Method method) {
  const auto spec = sym::SymmetrySpec::parseString(kBanditSpec, "mirror_bandit");
  model::ModelConfig mc;
  mc.method = method;
  mc.policy_hidden = {32, 32};
  mc.critic_hidden = {32, 32};
  model::ActorCritic<float> model(spec, mc);
  Rng rng(1234);
  model.initialize(rng);
  nn::Adam<float> adam(model.params());
  constexpr int kEnvs = 64, kHorizon = 8;
  config::PpoConfig ppo;
  ppo.minibatch_size = 128;
  ppo.mini_epochs = 4;
  ppo.learning_rate = 3e-3;
  ppo.kl_threshold = 0.008;
  PpoTrainer trainer(model, adam, ppo);
  RolloutBuffer buffer(kEnvs, kHorizon, spec.obsDim(), spec.actDim());
  MirrorBandit env(kEnvs, rng);

  constexpr int kUpdates = 40, kLast = 5;
  Curve c;
  for (int k = 0; k < kUpdates; ++k) {
    const double r = collect(model, env, buffer, rng);
    if (k == 0) c.initial = r;
    if (k >= kUpdates - kLast) c.final += r / kLast;
    trainer.update(buffer, rng);
  }
  return c;
}

// A random policy (std 1, mean near 0) earns about -3.7 per step; the optimum is 0.
TEST(PpoLearning, MasaAndSaLearnTheMirrorBandit) {
  for (auto method : {model::Method::kMasa, model::Method::kSa}) {
    const Curve c = train(method);
    SCOPED_TRACE(model::methodName(method));
    EXPECT_LT(c.initial, -3.0);
    EXPECT_GT(c.final, c.initial + 2.0);
    EXPECT_GT(c.final, -1.5);
    std::printf("[ %s ] mean reward per step: initial %.3f, final %.3f\n", model::methodName(method).c_str(),
                c.initial, c.final);
  }
}

}  // namespace
}  // namespace masa::ppo
