// What MASA guarantees offline, measured after some training on asymmetric random data (so that
// the parameters are not at their initial values): the BC and IQL policies are equivariant, V is
// invariant, and both Q networks and the target Q are symmetric under the joint transform,
// Q(T_i o, T_i a) = Q(o, a), through the fitted normalizer. SA's Q shows the check can fail.
#include <gtest/gtest.h>

#include "common/model/equivariance_check.hpp"
#include "learner/offline/bc_trainer.hpp"
#include "learner/offline/iql_trainer.hpp"
#include "learner/offline/normalizer_fit.hpp"
#include "learner/offline/state_action_maps.hpp"
#include "offline_test_support.hpp"

namespace masa::offline {
namespace {

// max_i,b,k |Q_k(T_i o, T_i a) - Q_k(o, a)| / (1 + |Q_k(o, a)|) of raw observations.
double qSymmetryError(const sym::SymmetrySpec& spec, model::ActorCritic<float>& model, TwinQ<float>& q,
                      const Mat<float>& obs, const Mat<float>& act) {
  const Eigen::Index b = obs.cols();
  Mat<float> obs_n(obs.rows(), b), tobs(obs.rows(), b), tobs_n(obs.rows(), b), tact(act.rows(), b);
  model.obsNormalizer().normalize(obs, obs_n);
  const Mat<float> q0 = q.forward(obs_n, act);
  double worst = 0;
  for (int i = 1; i < spec.numAgents(); ++i) {
    spec.obsTransform(i).apply<float>(obs, tobs);
    spec.actTransform(i).apply<float>(act, tact);
    model.obsNormalizer().normalize(tobs, tobs_n);
    const Mat<float> qi = q.forward(tobs_n, tact);
    worst = std::max(worst, static_cast<double>(((qi - q0).array().abs() / (1 + q0.array().abs())).maxCoeff()));
  }
  return worst;
}

struct Trained {
  model::ActorCritic<float> model;
  TwinQ<float> q, q_target;
  Trained(const sym::SymmetrySpec& spec, model::Method method, Algo algo, Rng& rng)
      : model(spec, test::smallOfflineModel(method, {24, 16}, {24, 16}, 1.0)), q(spec, method, {24, 16}, nn::Activation::kElu),
        q_target(spec, method, {24, 16}, nn::Activation::kElu) {
    model.initialize(rng);
    q.initialize(rng);
    q_target.moveTowards(q, 1.0f);
    const auto data = test::randomDataset(spec, 6, 10, rng);
    fitObservationNormalizer(model, data);
    auto cfg = test::smallOfflineConfig(algo, 30);
    cfg.learning_rate = 3e-3;  // move far from the initial parameters in few steps
    TransitionBatch<float> batch;
    if (algo == Algo::kIql) {
      IqlTrainer<float> iql(model, q, q_target, cfg);
      for (int s = 0; s < 30; ++s) {
        sampleBatch(data, 32, rng, batch);
        iql.step(batch);
      }
    } else {
      BcTrainer<float> bc(model, cfg);
      for (int s = 0; s < 30; ++s) {
        sampleBatch(data, 32, rng, batch);
        bc.step(batch);
      }
    }
  }
};

const char* const kOfflineSpecs[] = {test::kMirrorSpec, test::kC3Spec, test::kC4Spec};

TEST(OfflineSymmetry, MasaBcAndIqlPoliciesEquivariantValueInvariantAndQSymmetricTo1e5) {
  for (Algo algo : {Algo::kBc, Algo::kIql})
    for (const char* yaml : kOfflineSpecs) {
      const auto spec = test::spec(yaml, "spec");
      Rng rng(21);
      Trained t(spec, model::Method::kMasa, algo, rng);
      const Mat<float> obs = test::randomMatrix<float>(spec.obsDim(), 16, rng, 1.5, 0.3);
      const Mat<float> act = test::randomMatrix<float>(spec.actDim(), 16, rng);
      const auto r = model::checkEquivariance<float>(t.model, obs, act);
      const std::string what = algoName(algo) + " on " + spec.name();
      EXPECT_LT(r.mean_error, 1e-5) << what;
      EXPECT_LT(r.logp_error, 1e-5) << what;
      if (algo == Algo::kBc) continue;  // BC trains no V and no Q
      EXPECT_LT(r.value_error, 1e-5) << what;
      EXPECT_LT(qSymmetryError(spec, t.model, t.q, obs, act), 1e-5) << what;
      EXPECT_LT(qSymmetryError(spec, t.model, t.q_target, obs, act), 1e-5) << what;
    }
}

TEST(OfflineSymmetry, SaQIsNotSymmetricSoTheCheckCanFail) {
  const auto spec = test::spec(test::kC3Spec, "c3");
  Rng rng(23);
  Trained t(spec, model::Method::kSa, Algo::kIql, rng);
  const Mat<float> obs = test::randomMatrix<float>(spec.obsDim(), 16, rng, 1.5, 0.3);
  const Mat<float> act = test::randomMatrix<float>(spec.actDim(), 16, rng);
  EXPECT_GT(qSymmetryError(spec, t.model, t.q, obs, act), 1e-3);
}

TEST(OfflineSymmetry, JointTransformIsTheBlockDiagonalOfTheSpecsMapsAndAGroup) {
  const auto spec = test::spec(test::kC4Spec, "c4");
  const int o = spec.obsDim(), a = spec.actDim();
  for (int i = 0; i < 4; ++i) {
    const Eigen::MatrixXd j = stateActionTransform(spec, i).toDense();
    EXPECT_TRUE(j.topLeftCorner(o, o).isApprox(spec.obsTransform(i).toDense()));
    EXPECT_TRUE(j.bottomRightCorner(a, a).isApprox(spec.actTransform(i).toDense()));
    EXPECT_EQ(j.topRightCorner(o, a).norm(), 0.0);
    EXPECT_EQ(j.bottomLeftCorner(a, o).norm(), 0.0);
    const Eigen::MatrixXd j1 = stateActionTransform(spec, 1).toDense();
    EXPECT_TRUE((j1 * j).isApprox(stateActionTransform(spec, (i + 1) % 4).toDense())) << "J_1 J_" << i;
  }
}

}  // namespace
}  // namespace masa::offline
