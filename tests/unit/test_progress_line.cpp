// The learner's progress line says what it knows: the episodes that ended in the update, or that
// none did with the last ones that did, never "return nan" (issue #54: once the A1 walks to its
// time limit, every other update ended no episode and printed nan).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "learner/update_report.hpp"

namespace masa::learner {
namespace {

// What printProgress writes to stdout.
std::string progressLineOf(const UpdateReport& report) {
  testing::internal::CaptureStdout();
  printProgress(report, ReportColumns{}, 10, 1.0, 4);
  return testing::internal::GetCapturedStdout();
}

// One update of `episodes` episodes of return 100 u and length 10 u.
void summarizeUpdate(UpdateReport& report, int update, int episodes) {
  rollout::Rollout batch;
  batch.allocate(4, 8, 2, 1);
  batch.clearEvents();
  for (int e = 0; e < episodes; ++e) batch.addEpisode(e, 100.0f * update, 10 * update, -1, nullptr);
  report.update = update;
  summarizeEpisodes(batch, report);
}

TEST(ProgressLine, ShowsTheUpdatesEpisodesOrThatNoneEndedWithTheLastOnesNeverNan) {
  UpdateReport report;
  summarizeUpdate(report, 1, 0);
  std::string line = progressLineOf(report);
  EXPECT_NE(line.find("no episode ended yet"), std::string::npos) << line;
  summarizeUpdate(report, 2, 3);
  line = progressLineOf(report);
  EXPECT_NE(line.find("return 200.000  len 20.0"), std::string::npos) << line;
  summarizeUpdate(report, 3, 0);
  line = progressLineOf(report);
  EXPECT_NE(line.find("no episode ended (update 2's: return 200.000  len 20.0)"), std::string::npos) << line;
  for (const std::string& l : {line, progressLineOf(report)}) EXPECT_EQ(l.find("nan"), std::string::npos) << l;
  // metrics.csv keeps NaN for an update without episodes: a number there would read as a return.
  EXPECT_TRUE(std::isnan(report.mean_return));
}

}  // namespace
}  // namespace masa::learner
