// The text readers under random damage (docs/inputs.md gap 4): every shipped config (task, recipe,
// deploy, symmetry spec), a run key and a metrics.csv, mutated by file_mutations.hpp with seeded
// generators. Each damaged file must end in either a value the reader's checks accept or an error
// that names the file (or, for a run key, the key file's path), within a time bound, and never
// crash. A flipped digit in a config is still a valid config: text is not sealed, so "refused"
// cannot be asked of every mutation, only "named or within the checks".
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

#include "common/config/run_config.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "common/transport/run_key.hpp"
#include "deploy/runner/deploy_config.hpp"
#include "damaged_text.hpp"
#include "common/integrity/ed25519_keys.hpp"
#include "common/sim/registry.hpp"
#include "tasks/tasks.hpp"
#include "learner/run_dir/metrics_csv.hpp"

namespace fs = std::filesystem;

namespace {

using masa::test::DamagedText;
using masa::test::kMutationsPerFile;
using masa::test::readAll;
using masa::test::writeAll;

TEST_F(DamagedText, TaskFilesAndRecipesAreReadWithinTheirChecksOrRefusedNamingTheFile) {
  const std::string configs = (root_ / "configs").string();
  uint64_t seed = 1;
  for (const auto& e : fs::directory_iterator(root_ / "configs" / "tasks")) {
    const std::string task = e.path().stem().string();
    fuzz(e.path(), e.path().filename().string(), seed++, [&] {
      const masa::config::RunConfig rc = masa::config::loadRunConfig(configs, {"task=" + task});
      (void)rc;
    });
  }
  for (const auto& e : fs::directory_iterator(root_ / "configs" / "recipes"))
    fuzz(e.path(), e.path().filename().string(), seed++,
         [&] { (void)masa::config::loadRunConfig(configs, {"@" + e.path().string()}); });
  fuzz(root_ / "configs" / "defaults.yaml", "defaults.yaml", seed++,
       [&] { (void)masa::config::loadRunConfig(configs, {"task=a1_beam"}); });
  EXPECT_GT(refused_, 0);
  EXPECT_GT(accepted_, 0);
}

TEST_F(DamagedText, DeployConfigsAndSpecsAreReadWithinTheirChecksOrRefusedNamingTheFile) {
  uint64_t seed = 100;
  for (const auto& e : fs::directory_iterator(root_ / "configs" / "deploy"))
    fuzz(e.path(), e.path().filename().string(), seed++,
         [&] { (void)masa::deploy::loadDeployConfig(e.path().string()); });
  for (const auto& e : fs::directory_iterator(root_ / "configs" / "specs"))
    fuzz(e.path(), e.path().filename().string(), seed++,
         [&] { (void)masa::sym::SymmetrySpec::load(e.path().string()); });
  EXPECT_GT(refused_, 0);
}

TEST_F(DamagedText, ARunKeyIsExactlyRightOrRefusedNamingItsPath) {
  const fs::path key = root_ / "run.key";
  writeAll(key, std::string(64, 'a') + "\n");
  ::chmod(key.c_str(), 0600);
  const masa::transport::RunKey original = masa::transport::readRunKey(key.string());
  fuzz(key, key.string(), 7, [&] {
    ::chmod(key.c_str(), 0600);
    (void)masa::transport::readRunKey(key.string());
  });
  (void)original;
  EXPECT_GT(refused_, kMutationsPerFile / 2);
}

TEST_F(DamagedText, AMetricsFileIsCutAtTheCheckpointOrRefusedNamingIt) {
  const fs::path csv = root_ / "metrics.csv";
  std::string text = "update,env_steps,wall_time_s,return\n";
  for (int u = 1; u <= 20; ++u) text += std::to_string(u) + "," + std::to_string(1000 * u) + ",1.5,2.25\n";
  writeAll(csv, text);
  // What stays is the header and rows of the header's width whose update is at most the checkpoint's.
  fuzz(csv, "metrics.csv", 9, [&] {
    masa::learner::truncateMetricsCsv(csv.string(), 10);
    std::istringstream kept(readAll(csv));
    std::string header, row;
    std::getline(kept, header);
    const auto width = std::count(header.begin(), header.end(), ',');
    while (std::getline(kept, row)) {
      EXPECT_EQ(std::count(row.begin(), row.end(), ','), width) << "kept a row of another width: " << row;
      char* end = nullptr;
      const long long update = std::strtoll(row.c_str(), &end, 10);
      EXPECT_TRUE(end != row.c_str() && *end == ',' && update <= 10) << "kept a row past the checkpoint: " << row;
    }
  });
}

// PEM keys (OpenSSL's reader behind SigningKey and TrustedKeys): a damaged key file is refused
// naming it, or is still a key of its kind (a PEM body with a changed byte can be another valid key).
TEST_F(DamagedText, KeyFilesAreKeysOfTheirKindOrRefusedNamingTheFile) {
  const fs::path priv = root_ / "signer.key", pub = root_ / "signer.pub";
  masa::integrity::generateKeyPair(priv.string(), pub.string());
  fuzz(priv, priv.string(), 21, [&] {
    ::chmod(priv.c_str(), 0600);
    (void)masa::integrity::SigningKey::load(priv.string());
  });
  fuzz(pub, pub.string(), 22, [&] { (void)masa::integrity::TrustedKeys::load(pub.string()); });
  EXPECT_GT(refused_, kMutationsPerFile);
}

// Tasks written in YAML (task_code: yaml; docs/yaml_task.md): the task file read and the task built
// and stepped from its env section, as a training run does.
TEST_F(DamagedText, YamlTasksAreBuiltWithinTheirChecksOrRefusedNamingTheFile) {
  const std::string configs = (root_ / "configs").string();
  uint64_t seed = 300;
  for (const std::string task : {"a1_beam_yaml", "ant_acrobatic_yaml", "c4_walker"}) {
    const fs::path file = root_ / "configs" / "tasks" / (task + ".yaml");
    fuzz(file, task + ".yaml", seed++, [&] {
      const masa::config::RunConfig rc = masa::config::loadRunConfig(configs, {"task=" + task});
      const masa::task::TaskFactory factory(masa::task::taskCatalog(), task, masa::sym::SymmetrySpec::load(rc.spec_path),
                                            rc.env, rc.origin);
      std::unique_ptr<masa::task::Task> t = factory.create();
      masa::Rng rng(1);
      t->reset(rng);
      const std::vector<float> zero(static_cast<std::size_t>(t->actDim()), 0.0f);
      for (int k = 0; k < 5; ++k) (void)t->step(zero.data());
    });
  }
  EXPECT_GT(refused_, 0);
  EXPECT_GT(accepted_, 0);
}

}  // namespace
