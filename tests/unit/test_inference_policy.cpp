// The acting half of a model (common/model/inference_policy.hpp), what the actors and the robot
// runner hold: its parameters are exactly the ActorCritic's policy prefix (the broadcast and a
// policy file load as they are), and it acts bit for bit as the model does, for every method,
// squashed or not, normalizer included; initialized from a generator it draws the model's policy.
#include <gtest/gtest.h>

#include <filesystem>

#include "common/model/inference_policy.hpp"

namespace masa::model {
namespace {

sym::SymmetrySpec shippedSpec(const std::string& task) {
  return sym::SymmetrySpec::load((std::filesystem::path(MASA_SOURCE_DIR) / "configs/specs" / (task + ".yaml")).string());
}

ModelConfig smallModel(Method method) {
  ModelConfig c;
  c.method = method;
  c.policy_hidden = {24, 12};
  c.critic_hidden = {16};
  c.init_log_std = -0.3;
  return c;
}

TEST(InferencePolicy, ActsAsItsModelBitForBitWithTheModelsPolicyPrefixForEveryMethod) {
  for (const char* task : {"a1_beam", "ant_acrobatic", "trifinger_lift"}) {
    const auto spec = shippedSpec(task);
    for (Method method : {Method::kSa, Method::kSasa, Method::kMa, Method::kMasa}) {
      for (ActionSquash squash : {ActionSquash::kNone, ActionSquash::kTanh}) {
        SCOPED_TRACE(std::string(task) + " " + methodName(method) + " squash " + actionSquashName(squash));
        ModelConfig config = smallModel(method);
        config.squash = squash;
        ActorCritic<float> model(spec, config);
        Rng rng(11);
        model.initialize(rng);
        // The policy's last layer is initialized small: make its output (and tanh's) tell apart.
        model.params().values() += Vec<float>::Random(model.params().size()) * 0.3f;
        Mat<float> stats = Mat<float>::Random(spec.obsDim(), 64) * 3.0f;
        model.obsNormalizer().update(stats);

        const auto policy = InferencePolicy<float>::of(model);
        ASSERT_EQ(policy->params().size(), model.policyParamCount());
        EXPECT_LT(policy->params().size(), model.params().size()) << "no critic in the acting half";
        for (std::size_t k = 0; k < policy->params().segments().size(); ++k) {
          EXPECT_EQ(policy->params().segments()[k].name, model.params().segments()[k].name);
          EXPECT_EQ(policy->params().segments()[k].offset, model.params().segments()[k].offset);
        }

        const Mat<float> obs = Mat<float>::Random(spec.obsDim(), 5) * 2.0f;
        const Mat<float> expected = model.actMean(obs);
        const Mat<float> got = policy->actMean(obs);
        EXPECT_EQ((got - expected).cwiseAbs().maxCoeff(), 0.0f);
        Vec<float> ls_model(spec.actDim()), ls_policy(spec.actDim());
        model.logStd(ls_model);
        policy->logStd(ls_policy);
        EXPECT_EQ(ls_policy, ls_model);

        // Frozen (the runner), on one column: the packed-weights path, the same action.
        policy->freezeForInference();
        model.freezeForInference();
        const Mat<float> one = obs.leftCols(1);
        const Mat<float> expected_one = model.actMean(one);
        EXPECT_EQ((policy->actMean(one) - expected_one).cwiseAbs().maxCoeff(), 0.0f);
      }
    }
  }
}

TEST(InferencePolicy, InitializedFromAGeneratorItHoldsTheModelsPolicy) {
  const auto spec = shippedSpec("humanoid_tightrope");
  for (Method method : {Method::kSa, Method::kMasa}) {
    ActorCritic<float> model(spec, smallModel(method));
    InferencePolicy<float> policy(spec, smallModel(method));
    Rng a(5), b(5);
    model.initialize(a);
    policy.initialize(b);
    EXPECT_EQ(policy.params().values(), model.params().values().head(model.policyParamCount()))
        << methodName(method);
  }
}

TEST(InferencePolicy, RefusesObservationsOfAnotherSize) {
  const auto spec = shippedSpec("a1_beam");
  InferencePolicy<float> policy(spec, smallModel(Method::kMasa));
  const Mat<float> wrong = Mat<float>::Zero(spec.obsDim() + 1, 2);
  EXPECT_THROW(policy.actMean(wrong), std::exception);
}

}  // namespace
}  // namespace masa::model
