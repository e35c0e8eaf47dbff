// metrics.csv cut back to a checkpoint's update on resume (learner/run_dir/metrics_csv.hpp).
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "learner/run_dir/metrics_csv.hpp"

namespace masa::learner {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> lines(const fs::path& p) {
  std::ifstream f(p);
  std::vector<std::string> out;
  for (std::string s; std::getline(f, s);) out.push_back(s);
  return out;
}

fs::path csvWithRows(const std::string& name, int rows, const std::string& torn_tail = "") {
  const fs::path p = fs::temp_directory_path() / ("masa_test_metrics_" + name + "_" + std::to_string(::getpid()) + ".csv");
  std::ofstream f(p, std::ios::trunc);
  f << "update,env_steps,return\n";
  for (int k = 1; k <= rows; ++k) f << k << ',' << 1000 * k << ",-3.5\n";
  f << torn_tail;
  return p;
}

TEST(MetricsCsv, ResumeFromUpdateSixKeepsTheHeaderAndUpdatesOneToSix) {
  const fs::path p = csvWithRows("cut", 10);
  EXPECT_EQ(truncateMetricsCsv(p.string(), 6), 4);
  const auto got = lines(p);
  ASSERT_EQ(got.size(), 7u);
  EXPECT_EQ(got[0], "update,env_steps,return");
  for (int k = 1; k <= 6; ++k) EXPECT_EQ(got[k], std::to_string(k) + ',' + std::to_string(1000 * k) + ",-3.5");
  fs::remove(p);
}

// A run recorded before the update had one name (epoch from 0, version = epoch + 1), resumed by
// today's learner: the file becomes today's form, so the rows the resumed run appends line up.
TEST(MetricsCsv, AnOldRunsEpochAndVersionColumnsBecomeOneUpdateColumnOnResume) {
  const fs::path p = fs::temp_directory_path() / ("masa_test_metrics_old_" + std::to_string(::getpid()) + ".csv");
  {
    std::ofstream f(p, std::ios::trunc);
    f << "epoch,version,env_steps,return\n";
    for (int k = 0; k < 8; ++k) f << k << ',' << k + 1 << ',' << 1000 * (k + 1) << ",-3.5\n";
  }
  EXPECT_EQ(truncateMetricsCsv(p.string(), 6), 2);
  const auto got = lines(p);
  ASSERT_EQ(got.size(), 7u);
  EXPECT_EQ(got[0], "update,env_steps,return");
  for (int k = 1; k <= 6; ++k) EXPECT_EQ(got[k], std::to_string(k) + ',' + std::to_string(1000 * k) + ",-3.5");
  // Nothing past the checkpoint: still rewritten in today's form.
  {
    std::ofstream f(p, std::ios::trunc);
    f << "epoch,version,env_steps,return\n0,1,1000,-3.5\n";
  }
  EXPECT_EQ(truncateMetricsCsv(p.string(), 1), 0);
  EXPECT_EQ(lines(p), (std::vector<std::string>{"update,env_steps,return", "1,1000,-3.5"}));
  fs::remove(p);
}

TEST(MetricsCsv, ARowTornByTheKillIsDroppedAndAFileWithNothingPastTheCheckpointIsLeftAlone) {
  const fs::path torn = csvWithRows("torn", 6, "7,70");  // killed while writing update 7
  EXPECT_EQ(truncateMetricsCsv(torn.string(), 6), 1);
  EXPECT_EQ(lines(torn).size(), 7u);
  const fs::path p2 = csvWithRows("torn_early", 3, "1\n");  // a short row among the kept numbers
  EXPECT_EQ(truncateMetricsCsv(p2.string(), 6), 1);
  EXPECT_EQ(lines(p2).size(), 4u);
  const fs::path whole = csvWithRows("whole", 6);
  const auto before = lines(whole);
  EXPECT_EQ(truncateMetricsCsv(whole.string(), 6), 0);
  EXPECT_EQ(lines(whole), before);
  EXPECT_EQ(truncateMetricsCsv((whole.string() + ".missing"), 6), 0);
  EXPECT_FALSE(fs::exists(whole.string() + ".missing"));
  fs::remove(torn);
  fs::remove(p2);
  fs::remove(whole);
}

}  // namespace
}  // namespace masa::learner
