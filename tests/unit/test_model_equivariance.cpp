// MASA's guarantee checked numerically on the whole pipeline (normalizer + policy mean + tied std
// + log-prob + critic), and the same check shown to catch the missing symmetry of SA and MA.
#include <gtest/gtest.h>

#include <filesystem>

#include "common/model/equivariance_check.hpp"
#include "model_test_support.hpp"

namespace masa::model {
namespace {

template <typename S>
EquivarianceReport measure(const sym::SymmetrySpec& spec, Method method, std::uint64_t seed) {
  ModelConfig cfg;
  cfg.method = method;
  cfg.policy_hidden = {32, 16};
  cfg.critic_hidden = {32, 16};
  cfg.critic_head_hidden = {8};
  cfg.policy_last_layer_scale = 1.0;  // O(1) outputs, so a violation cannot hide in tiny numbers
  cfg.init_log_std = -0.3;
  ActorCritic<S> model(spec, cfg);
  Rng rng(seed);
  model.initialize(rng);
  // Non-trivial, non-symmetric data statistics: the normalizer must symmetrize them itself.
  model.obsNormalizer().update(test::randomMatrix<S>(spec.obsDim(), 200, rng, 2.0, 0.7));
  const Mat<S> obs = test::randomMatrix<S>(spec.obsDim(), 16, rng, 1.5, 0.3);
  const Mat<S> act = test::randomMatrix<S>(spec.actDim(), 16, rng);
  return checkEquivariance<S>(model, obs, act);
}

struct NamedSpec {
  const char* yaml;
  const char* name;
};
const NamedSpec kSpecs[] = {{test::kMirrorSpec, "mirror"}, {test::kC3Spec, "c3"}, {test::kC4Spec, "c4"}};

TEST(MasaEquivariance, HoldsToRoundingInDoubleForMirrorC3AndC4) {
  for (const auto& s : kSpecs) {
    const auto r = measure<double>(test::spec(s.yaml, s.name), Method::kMasa, 1);
    EXPECT_LT(r.mean_error, 1e-10) << s.name;
    EXPECT_LT(r.logp_error, 1e-10) << s.name;
    EXPECT_LT(r.value_error, 1e-10) << s.name;
  }
}

TEST(MasaEquivariance, HoldsTo1e5InFloatForMirrorC3AndC4) {
  for (const auto& s : kSpecs) {
    const auto r = measure<float>(test::spec(s.yaml, s.name), Method::kMasa, 2);
    EXPECT_LT(r.mean_error, 1e-5) << s.name;
    EXPECT_LT(r.logp_error, 1e-5) << s.name;
    EXPECT_LT(r.value_error, 1e-5) << s.name;
  }
}

TEST(MasaEquivariance, HoldsForEveryShippedSpec) {
  const std::filesystem::path dir = std::filesystem::path(MASA_SOURCE_DIR) / "configs" / "specs";
  int checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    const auto spec = sym::SymmetrySpec::load(entry.path().string());
    const auto r = measure<float>(spec, Method::kMasa, 3);
    EXPECT_LT(r.worst(), 1e-5) << entry.path();
    ++checked;
  }
  EXPECT_GE(checked, 5) << "expected a spec for each of the five tasks in " << dir;
}

TEST(MasaEquivariance, CheckReportsClearViolationForSaAndMa) {
  for (const auto& s : kSpecs) {
    for (Method m : {Method::kSa, Method::kMa}) {
      const auto r = measure<double>(test::spec(s.yaml, s.name), m, 4);
      EXPECT_GT(r.mean_error, 1e-2) << s.name << " " << methodName(m) << ": the check must see the missing symmetry";
      EXPECT_GT(r.worst(), 1e-2) << s.name << " " << methodName(m);
    }
  }
}

TEST(MasaEquivariance, SasaIsNotEquivariantByConstructionOnlyByItsLoss) {
  const auto r = measure<double>(test::spec(test::kMirrorSpec, "mirror"), Method::kSasa, 5);
  EXPECT_GT(r.mean_error, 1e-2);
}

}  // namespace
}  // namespace masa::model
