// Policy files (what inference needs, written by the learner next to its checkpoint), the
// evaluator that measures them, and the policies shipped in tasks/<task>/policy/.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <unistd.h>

#include "common/config/run_config.hpp"
#include "common/core/config_error.hpp"
#include "common/policy/policy_file.hpp"
#include "common/sim/policy_evaluator.hpp"
#include "tasks/tasks.hpp"

namespace masa::policy {
namespace {

namespace fs = std::filesystem;

fs::path tempFile(const std::string& name) {
  return fs::temp_directory_path() / ("masa_test_policy_" + name + "_" + std::to_string(::getpid()));
}

config::RunConfig smallPolicyConfig(const std::string& task, const std::string& method) {
  return config::loadRunConfig(config::defaultConfigsDir(),
                               {"task=" + task, "method=" + method, "model.policy_hidden=[16]",
                                "model.critic_hidden=[16]", "env.max_episode_steps=30"});
}

TEST(PolicyFile, RoundTripsConfigSpecNetworksAndNormalizerBitForBit) {
  const config::RunConfig rc = smallPolicyConfig("ant_acrobatic", "masa");
  const auto spec = sym::SymmetrySpec::load(rc.spec_path);
  model::ActorCritic<float> m(spec, rc.model);
  Rng rng(3);
  m.initialize(rng);
  Mat<float> batch = Mat<float>::Random(spec.obsDim(), 64);
  m.obsNormalizer().update(batch);
  const fs::path f = tempFile("roundtrip");
  savePolicyFile(f.string(), rc, m);
  ASSERT_TRUE(isPolicyFile(f.string()));

  LoadedPolicy p = loadPolicyFile(f.string());
  EXPECT_EQ(p.config.task, "ant_acrobatic");
  EXPECT_EQ(p.config.method, model::Method::kMasa);
  EXPECT_EQ(p.config.model.policy_hidden, std::vector<int>{16});
  EXPECT_EQ(p.config.env["max_episode_steps"].as<int>(), 30);
  EXPECT_EQ(p.spec.obsDim(), spec.obsDim());
  const Mat<float> want = m.actMean(batch);
  const Mat<float> got = p.model->actMean(batch);
  EXPECT_EQ((want - got).cwiseAbs().maxCoeff(), 0.0f);
  EXPECT_LT(checkPolicySymmetry(p), 1e-5);
  fs::remove(f);
}

TEST(PolicyFile, ATruncatedOrForeignFileIsRefusedWithItsName) {
  const config::RunConfig rc = smallPolicyConfig("a1_beam", "sa");
  const auto spec = sym::SymmetrySpec::load(rc.spec_path);
  model::ActorCritic<float> m(spec, rc.model);
  Rng rng(3);
  m.initialize(rng);
  const fs::path f = tempFile("truncated");
  savePolicyFile(f.string(), rc, m);
  fs::resize_file(f, fs::file_size(f) / 2);
  try {
    loadPolicyFile(f.string());
    FAIL() << "a truncated policy file was loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(f.string()), std::string::npos) << e.what();
  }
  std::ofstream(f) << "not a policy";
  EXPECT_FALSE(isPolicyFile(f.string()));
  EXPECT_THROW(loadPolicyFile(f.string()), std::runtime_error);
  fs::remove(f);
}

TEST(PolicyFile, AMasaPolicyWhoseSpecWasSwappedFailsTheEquivarianceCheckOnLoad) {
  // A C2 mirror policy trained on a1_beam, checked against a spec whose mirror maps another way:
  // build the model under a1_beam's spec, then perturb its weights asymmetrically is impossible
  // (MASA is equivariant by construction), so break the normalizer instead: statistics that are
  // not orbit-symmetric make the whole pipeline non-equivariant.
  const config::RunConfig rc = smallPolicyConfig("a1_beam", "masa");
  const auto spec = sym::SymmetrySpec::load(rc.spec_path);
  LoadedPolicy p;
  p.config = rc;
  p.spec = spec;
  p.source = "test";
  p.model = std::make_unique<model::ActorCritic<float>>(spec, rc.model);
  Rng rng(5);
  p.model->initialize(rng);
  std::vector<float> mean(spec.obsDim(), 0.0f), std(spec.obsDim(), 1.0f);
  mean[0] = 3.0f;  // trunk_y is odd under the mirror: a non-zero mean breaks the symmetry
  p.model->obsNormalizer().setMeanStd(mean.data(), std.data());
  EXPECT_THROW(checkPolicySymmetry(p), std::runtime_error);
}

TEST(PolicyFile, AMasaPolicyWithANonFiniteOutputFailsTheEquivarianceCheck) {
  // MASA is equivariant by construction for any finite parameters; a NaN or infinite one makes
  // outputs that are no symmetry's image. The check dropped NaN errors (error 0) and let a policy
  // whose mean held a NaN through masa_eval, masa_deploy and masa_export (issue #54).
  const config::RunConfig rc = smallPolicyConfig("a1_beam", "masa");
  const auto spec = sym::SymmetrySpec::load(rc.spec_path);
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    LoadedPolicy p;
    p.config = rc;
    p.spec = spec;
    p.source = "test";
    p.model = std::make_unique<model::ActorCritic<float>>(spec, rc.model);
    Rng rng(5);
    p.model->initialize(rng);
    EXPECT_LT(checkPolicySymmetry(p), 1e-5);
    auto& values = p.model->params().values();
    values(values.size() - 1) = bad;  // the last parameter (the critic's output bias)
    EXPECT_THROW(checkPolicySymmetry(p), std::runtime_error) << bad;
  }
}

// docs/inputs.md gap 3: an env setting of NaN or infinity (a reward weight, a gain) is refused
// when the task is built, naming the key.
TEST(TaskFactory, ANaNOrInfiniteEnvSettingIsRefusedNamingTheKey) {
  for (const std::string v : {".nan", ".inf"}) {
    try {
      const auto rc = config::loadRunConfig(config::defaultConfigsDir(), {"task=a1_beam", "env.weights.velocity=" + v});
      const auto spec = sym::SymmetrySpec::load(rc.spec_path);
      task::TaskFactory(task::taskCatalog(), rc.task, spec, rc.env, rc.origin).create();
      ADD_FAILURE() << "env.weights.velocity=" << v << " was taken";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), "env.weights.velocity");
      EXPECT_NE(std::string(e.what()).find("finite"), std::string::npos) << e.what();
    }
  }
}

TEST(PolicyEvaluator, EpisodesDependOnTheirSeedsOnlyNotOnTheBatchOrThreads) {
  const config::RunConfig rc = smallPolicyConfig("a1_beam", "masa");
  const auto spec = sym::SymmetrySpec::load(rc.spec_path);
  model::ActorCritic<float> m(spec, rc.model);
  Rng rng(9);
  m.initialize(rng);
  task::TaskFactory factory(task::taskCatalog(), rc.task, spec, rc.env, rc.origin);
  task::PolicyEvaluator ev(factory, m);
  task::EvalOptions o;
  o.episodes = 4;
  o.seed = 10;
  o.deterministic = false;
  o.threads = 2;
  const task::EvalSummary all = ev.run(o);
  ASSERT_EQ(all.episodes.size(), 4u);
  EXPECT_EQ(all.progress_names, (std::vector<std::string>{"distance_m", "speed_mps"}));
  // Episode 2 alone, from its own seed, one thread.
  o.episodes = 1;
  o.seed = 12;
  o.threads = 1;
  const task::EvalSummary one = ev.run(o);
  EXPECT_EQ(one.episodes[0].seed, 12u);
  EXPECT_EQ(one.episodes[0].length, all.episodes[2].length);
  EXPECT_DOUBLE_EQ(one.episodes[0].ret, all.episodes[2].ret);
  EXPECT_DOUBLE_EQ(one.episodes[0].progress[0], all.episodes[2].progress[0]);
  // Summary statistics are those of the episodes.
  double sum = 0;
  for (const auto& e : all.episodes) sum += e.ret;
  EXPECT_NEAR(all.ret.mean, sum / 4, 1e-9);
  EXPECT_EQ(all.success_rate, -1.0);  // a1_beam has no success notion
}

// Every policy shipped with a task loads with its own config and spec, passes the equivariance
// check (MASA), and runs in its task.
TEST(ShippedPolicies, EveryTaskShipsAPolicyThatLoadsChecksAndRuns) {
  const fs::path tasks = fs::path(MASA_SOURCE_DIR) / "tasks";
  int found = 0;
  for (const auto& dir : fs::directory_iterator(tasks)) {
    if (!dir.is_directory()) continue;
    const fs::path f = dir.path() / "policy" / "policy.bin";
    SCOPED_TRACE(f.string());
    ASSERT_TRUE(fs::exists(f)) << "task " << dir.path().filename() << " ships no trained policy";
    LoadedPolicy p = loadPolicyFile(f.string());
    EXPECT_EQ(p.config.task, dir.path().filename().string());
    if (p.config.method == model::Method::kMasa) {
      EXPECT_LT(checkPolicySymmetry(p), 1e-4);
    }
    task::TaskFactory factory(task::taskCatalog(), p.config.task, p.spec, p.config.env, p.config.origin);
    task::PolicyEvaluator ev(factory, *p.model);
    task::EvalOptions o;
    o.episodes = 1;
    o.max_steps = 20;
    const task::EvalSummary s = ev.run(o);
    EXPECT_GT(s.episodes[0].length, 0);
    ++found;
  }
  EXPECT_EQ(found, 5);
}

}  // namespace
}  // namespace masa::policy
