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
#include "file_mutations.hpp"
#include "learner/metrics_csv.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kConfigs = MASA_SOURCE_DIR "/configs";
constexpr int kMutationsPerFile = 25;
constexpr double kSecondsPerRead = 2.0;

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void writeAll(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

// A scratch copy of configs/ (and the models it points at stay where they are: paths in the
// configs are relative to the source tree's configs' parent, so the copy sits beside a link).
class DamagedText : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("masa_text_fuzz_" + std::to_string(::getpid()) + "_" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
    fs::copy(kConfigs, root_ / "configs", fs::copy_options::recursive);
    for (const char* linked : {"tasks", "tests"}) fs::create_directory_symlink(MASA_SOURCE_DIR "/" + std::string(linked), root_ / linked);
  }
  void TearDown() override { fs::remove_all(root_); }

  // Mutates `file` kMutationsPerFile times (restoring it after each) and calls `read`: it must
  // return or throw a std::exception whose message holds `name`, within the time bound.
  void fuzz(const fs::path& file, const std::string& name, uint64_t seed, const std::function<void()>& read) {
    const std::string original = readAll(file);
    std::mt19937_64 rng(seed);
    for (int i = 0; i < kMutationsPerFile; ++i) {
      const masa::fuzz::FileMutation m = masa::fuzz::mutateFile(original, rng);
      writeAll(file, m.bytes);
      const auto t0 = std::chrono::steady_clock::now();
      try {
        read();
        ++accepted_;
      } catch (const std::exception& e) {
        ++refused_;
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos)
            << file.filename() << ", " << m.what << ": the error does not name the file: " << e.what();
      }
      EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), kSecondsPerRead)
          << file.filename() << ", " << m.what;
    }
    writeAll(file, original);
  }

  fs::path root_;
  int accepted_ = 0, refused_ = 0;
};

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

}  // namespace
