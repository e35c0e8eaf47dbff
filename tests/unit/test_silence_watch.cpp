// The learner's word when rollout data stops: after the bound, naming the actors last heard.
#include <gtest/gtest.h>

#include "learner/silence_watch.hpp"

using masa::learner::SilenceWatch;
using std::chrono::seconds;

TEST(SilenceWatch, SaysNothingWhileDataArrivesAndNamesTheActorsOnceItStops) {
  const auto t0 = SilenceWatch::Clock::time_point{};
  SilenceWatch w(30.0, t0);
  w.heard(0, t0 + seconds(1));
  w.heard(1, t0 + seconds(2));
  w.heard(0, t0 + seconds(10));
  EXPECT_FALSE(w.check(t0 + seconds(39), 7, 0));  // 29 s since actor 0's last chunk
  const auto said = w.check(t0 + seconds(41), 7, 0);
  ASSERT_TRUE(said);
  EXPECT_NE(said->find("no rollout data for 31 s (at update 7)"), std::string::npos) << *said;
  EXPECT_NE(said->find("actor 0 31 s ago (2 chunks)"), std::string::npos) << *said;
  EXPECT_NE(said->find("actor 1 39 s ago (1 chunks)"), std::string::npos) << *said;
  EXPECT_EQ(said->find("dropped"), std::string::npos) << *said;
  // Once per interval while the silence lasts.
  EXPECT_FALSE(w.check(t0 + seconds(50), 7, 0));
  EXPECT_TRUE(w.check(t0 + seconds(72), 7, 0));
  // Data again: quiet until a new silence of 30 s.
  w.heard(1, t0 + seconds(80));
  EXPECT_FALSE(w.check(t0 + seconds(100), 8, 0));
  EXPECT_TRUE(w.check(t0 + seconds(111), 8, 0));
}

TEST(SilenceWatch, NoActorYetAndChunksDroppedDuringTheSilenceAreSaid) {
  const auto t0 = SilenceWatch::Clock::time_point{};
  SilenceWatch w(5.0, t0);
  EXPECT_FALSE(w.check(t0 + seconds(1), 0, 100));  // 100 drops before the silence: not counted
  const auto said = w.check(t0 + seconds(6), 0, 160);
  ASSERT_TRUE(said);
  EXPECT_NE(said->find("no actor heard from yet"), std::string::npos) << *said;
  EXPECT_NE(said->find("60 chunks dropped meanwhile"), std::string::npos) << *said;
}

TEST(SilenceWatch, ZeroNeverWarns) {
  const auto t0 = SilenceWatch::Clock::time_point{};
  SilenceWatch w(0.0, t0);
  EXPECT_FALSE(w.check(t0 + seconds(100000), 0, 0));
}

// What stops data-parallel ranks whose actors died: the time since the last accepted chunk, from the
// start when none came, and back to zero with the next chunk.
TEST(SilenceWatch, SilentForCountsFromTheStartOrTheLastChunk) {
  const auto t0 = SilenceWatch::Clock::time_point{};
  SilenceWatch w(30.0, t0);
  EXPECT_DOUBLE_EQ(w.silentFor(t0 + seconds(7)), 7.0);
  w.heard(3, t0 + seconds(10));
  EXPECT_DOUBLE_EQ(w.silentFor(t0 + seconds(10)), 0.0);
  EXPECT_DOUBLE_EQ(w.silentFor(t0 + seconds(135)), 125.0);
  w.check(t0 + seconds(140), 2, 0);  // a warning does not reset it
  EXPECT_DOUBLE_EQ(w.silentFor(t0 + seconds(140)), 130.0);
}

// The time the learner spends updating (an off-policy round's gradient steps: tens of seconds) is
// not silence of the actors: before the fix the learner said "no rollout data for 50 s" after
// every such round of a healthy masa_train run.
TEST(SilenceWatch, TheLearnersOwnBusyTimeIsNotSilence) {
  const auto t0 = SilenceWatch::Clock::time_point{};
  SilenceWatch w(30.0, t0);
  w.heard(0, t0 + seconds(1));
  w.learnerWasBusy(seconds(45));  // an update from t0 + 1 s to t0 + 46 s
  EXPECT_FALSE(w.check(t0 + seconds(46), 3, 0));
  EXPECT_DOUBLE_EQ(w.silentFor(t0 + seconds(50)), 4.0);
  // Real silence after it still counts.
  const auto said = w.check(t0 + seconds(77), 3, 0);
  ASSERT_TRUE(said);
  EXPECT_NE(said->find("no rollout data for 31 s"), std::string::npos) << *said;
}
