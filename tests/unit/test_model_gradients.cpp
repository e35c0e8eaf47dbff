// Gradients of every model against central finite differences, in double precision, over every
// parameter: the policy mean, the tied log-std, the critic and (for SASA) the symmetry losses.
#include <gtest/gtest.h>

#include "common/model/actor_critic.hpp"
#include "model_test_support.hpp"

namespace masa::model {
namespace {

struct Weights {
  Mat<double> mean, value;
  Vec<double> log_std;
};

// L = <Wm, mean> + <Wv, value> + <wl, log_std> (+ SASA losses, which backward adds itself).
double loss(ActorCritic<double>& m, const Mat<double>& obs, const Weights& w) {
  m.forward(obs);
  Vec<double> ls(m.actDim());
  m.logStd(ls);
  return w.mean.cwiseProduct(m.mean()).sum() + w.value.cwiseProduct(m.value()).sum() + w.log_std.dot(ls) +
         m.symmetryPolicyLoss() + m.symmetryValueLoss();
}

test::GradientCheckResult checkModel(const sym::SymmetrySpec& spec, Method method, bool include_sasa = true) {
  ModelConfig cfg;
  cfg.method = method;
  cfg.policy_hidden = {12, 7};
  cfg.critic_hidden = {10, 6};
  cfg.critic_head_hidden = {5};
  cfg.policy_last_layer_scale = 1.0;
  cfg.sasa_policy_coef = include_sasa ? 0.7 : 0.0;
  cfg.sasa_value_coef = include_sasa ? 0.3 : 0.0;
  ActorCritic<double> m(spec, cfg);
  Rng rng(42);
  m.initialize(rng);
  m.obsNormalizer().update(test::randomMatrix<double>(spec.obsDim(), 50, rng, 1.5, 0.2));
  const Mat<double> obs = test::randomMatrix<double>(spec.obsDim(), 5, rng);
  Weights w{test::randomMatrix<double>(spec.actDim(), 5, rng), test::randomMatrix<double>(1, 5, rng),
            test::randomMatrix<double>(spec.actDim(), 1, rng).col(0)};

  m.params().zeroGrad();
  m.forward(obs);
  m.backward(w.mean, w.log_std, w.value);
  const Vec<double> analytic = m.params().grads();
  return test::checkGradient(m.params().values(), analytic, [&] { return loss(m, obs, w); });
}

TEST(ModelGradient, MasaPolicyAndCriticMatchFiniteDifferencesOnMirror) {
  const auto r = checkModel(test::spec(test::kMirrorSpec, "mirror"), Method::kMasa);
  EXPECT_GT(r.analytic_norm, 1e-3);
  EXPECT_LT(r.max_relative_error, 1e-4) << "worst parameter index " << r.worst_index;
}

TEST(ModelGradient, MasaPolicyAndCriticMatchFiniteDifferencesOnC3AndC4) {
  for (const char* yaml : {test::kC3Spec, test::kC4Spec}) {
    const auto r = checkModel(test::spec(yaml, "rot"), Method::kMasa);
    EXPECT_GT(r.analytic_norm, 1e-3);
    EXPECT_LT(r.max_relative_error, 1e-4) << "worst parameter index " << r.worst_index;
  }
}

TEST(ModelGradient, SasaSymmetryLossesMatchFiniteDifferences) {
  for (const char* yaml : {test::kMirrorSpec, test::kC3Spec, test::kC4Spec}) {
    const auto r = checkModel(test::spec(yaml, "sasa"), Method::kSasa);
    EXPECT_GT(r.analytic_norm, 1e-3);
    EXPECT_LT(r.max_relative_error, 1e-4) << "worst parameter index " << r.worst_index;
  }
}

TEST(ModelGradient, SaAndMaMatchFiniteDifferences) {
  for (Method m : {Method::kSa, Method::kMa}) {
    const auto r = checkModel(test::spec(test::kC4Spec, "c4"), m);
    EXPECT_LT(r.max_relative_error, 1e-4) << methodName(m) << " worst parameter index " << r.worst_index;
  }
}

TEST(ModelGradient, SasaLossesAreZeroForOtherMethodsAndPositiveForSasa) {
  const auto spec = test::spec(test::kMirrorSpec, "mirror");
  Rng rng(7);
  const Mat<double> obs = test::randomMatrix<double>(spec.obsDim(), 4, rng);
  for (Method method : {Method::kMasa, Method::kSa, Method::kMa, Method::kSasa}) {
    ModelConfig cfg;
    cfg.method = method;
    cfg.policy_hidden = {8};
    cfg.critic_hidden = {8};
    cfg.policy_last_layer_scale = 1.0;
    ActorCritic<double> m(spec, cfg);
    m.initialize(rng);
    m.forward(obs);
    if (method == Method::kSasa) {
      EXPECT_GT(m.symmetryPolicyLoss(), 1e-4);
      EXPECT_GT(m.symmetryValueLoss(), 1e-6);
    } else {
      EXPECT_EQ(m.symmetryPolicyLoss(), 0.0);
      EXPECT_EQ(m.symmetryValueLoss(), 0.0);
    }
  }
}

}  // namespace
}  // namespace masa::model
