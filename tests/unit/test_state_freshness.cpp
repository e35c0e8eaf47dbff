// deploy/runner/state_freshness.hpp: which robot states are news. A forged far-future utime must
// not make the robot's real states repeats (docs/inputs.md gap 2); a robot whose clock restarts
// or steps is followed again after a few consistent states; a repeated state stays a repeat.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "deploy/runner/state_freshness.hpp"

namespace masa::deploy {
namespace {

using V = StateFreshness::Verdict;
constexpr int64_t kPeriod = 5000;  // 200 Hz, in microseconds
constexpr int64_t kLead = 25000;

// The robot's clock is ahead of ours by `offset` and each state arrives `delay` after its stamp.
struct Robot {
  int64_t offset = 1'700'000'000'000'000, t = 1'000'000;
  int64_t utime() const { return t + offset; }
};

TEST(StateFreshness, RealStatesAreNewAndARepeatIsNot) {
  StateFreshness f(kLead);
  Robot r;
  for (int k = 0; k < 100; ++k, r.t += kPeriod) ASSERT_EQ(f.judge(r.utime(), r.t + (k % 7) * 300), V::kNew) << k;
  const int64_t last = r.utime() - kPeriod;
  for (int k = 0; k < 10; ++k) EXPECT_EQ(f.judge(last, r.t + k * kPeriod), V::kRepeat) << "the same state again, " << k;
  EXPECT_EQ(f.resyncs(), 0);
}

TEST(StateFreshness, OneForgedFarFutureStateDoesNotHideTheRobotsNextStates) {
  for (const int64_t forged : {std::numeric_limits<int64_t>::max(), int64_t{1'800'000'000'000'000}}) {
    StateFreshness f(kLead);
    Robot r;
    for (int k = 0; k < 20; ++k, r.t += kPeriod) ASSERT_EQ(f.judge(r.utime(), r.t), V::kNew);
    EXPECT_EQ(f.judge(forged, r.t - kPeriod / 2), V::kAhead);
    for (int k = 0; k < 50; ++k, r.t += kPeriod) ASSERT_EQ(f.judge(r.utime(), r.t), V::kNew) << "state " << k << " after the forgery";
    EXPECT_EQ(f.refusedAhead(), 1);
    EXPECT_EQ(f.resyncs(), 0);
  }
}

TEST(StateFreshness, AStateLateOnTheNetworkDoesNotLockOutTheOnesAfterIt) {
  StateFreshness f(kLead);
  Robot r;
  for (int k = 0; k < 20; ++k, r.t += kPeriod) ASSERT_EQ(f.judge(r.utime(), r.t + 200), V::kNew);
  // One state delayed by 80 ms (more than the lead), then the rest on time again.
  ASSERT_EQ(f.judge(r.utime(), r.t + 80000), V::kNew);
  r.t += kPeriod;
  for (int k = 0; k < 20; ++k, r.t += kPeriod) ASSERT_EQ(f.judge(r.utime(), r.t + 200), V::kNew) << k;
}

TEST(StateFreshness, ALongPauseOfTheRobotIsNoLead) {
  StateFreshness f(kLead);
  Robot r;
  for (int k = 0; k < 5; ++k, r.t += kPeriod) ASSERT_EQ(f.judge(r.utime(), r.t), V::kNew);
  r.t += 10'000'000;  // 10 s without state: its next stamp jumps as far as the receive clock
  EXPECT_EQ(f.judge(r.utime(), r.t), V::kNew);
}

TEST(StateFreshness, ARobotWhoseClockRestartsOrStepsIsFollowedAfterThreeConsistentStates) {
  for (const int64_t step : {int64_t{-1'700'000'000'000'000}, int64_t{3'600'000'000}}) {  // reset to ~0; one hour ahead
    StateFreshness f(kLead);
    Robot r;
    for (int k = 0; k < 20; ++k, r.t += kPeriod) ASSERT_EQ(f.judge(r.utime(), r.t), V::kNew);
    r.offset += step;
    EXPECT_NE(f.judge(r.utime(), r.t), V::kNew);
    r.t += kPeriod;
    EXPECT_NE(f.judge(r.utime(), r.t), V::kNew);
    r.t += kPeriod;
    EXPECT_EQ(f.judge(r.utime(), r.t), V::kResynced);
    r.t += kPeriod;
    for (int k = 0; k < 20; ++k, r.t += kPeriod) ASSERT_EQ(f.judge(r.utime(), r.t), V::kNew) << k;
    EXPECT_EQ(f.resyncs(), 1);
  }
}

TEST(StateFreshness, RefusedStatesThatDoNotFormAConsistentStreamNeverResync) {
  StateFreshness f(kLead);
  Robot r;
  for (int k = 0; k < 20; ++k, r.t += kPeriod) ASSERT_EQ(f.judge(r.utime(), r.t), V::kNew);
  const int64_t now = r.t;
  // Forgeries, one a period: each further ahead than the clock allows from the one before.
  for (int k = 0; k < 30; ++k) EXPECT_EQ(f.judge(r.utime() + 1'000'000 + k * 1'000'000, now + k * kPeriod), V::kAhead) << k;
  // An old state sent again and again.
  for (int k = 0; k < 30; ++k) EXPECT_EQ(f.judge(r.utime() - kPeriod, now + k * kPeriod), V::kRepeat) << k;
  EXPECT_EQ(f.resyncs(), 0);
}

// Issue #55, item 2: a forger on an unsigned state channel sends, after every real state, one state
// a little less than the lead ahead of the newest state taken. Each alone is within the lead; if a
// taken state moved the lead, they would walk it forward without end and every real state would be
// a repeat from then on. The lead stays where the baseline put it: the forgeries beyond it are
// refused as ahead, and the robot's own states are news again within one lead.
TEST(StateFreshness, ForgedStatesInterleavedWithTheRealOnesCannotWalkTheLeadForward) {
  StateFreshness f(kLead);
  Robot r;
  for (int k = 0; k < 20; ++k, r.t += kPeriod) ASSERT_EQ(f.judge(r.utime(), r.t), V::kNew);
  int64_t forged = r.utime() - kPeriod;  // the newest taken
  int real_new = 0, forged_taken = 0, last_real_refused = -1;
  constexpr int kSteps = 200;  // one second
  for (int k = 0; k < kSteps; ++k, r.t += kPeriod) {
    if (f.judge(r.utime(), r.t) == V::kNew) ++real_new; else last_real_refused = k;
    forged += kLead * 9 / 10;
    const V v = f.judge(forged, r.t + kPeriod / 2);
    if (v == V::kNew || v == V::kResynced) ++forged_taken;
  }
  EXPECT_LE(forged_taken, 1) << "only a forgery inside the baseline's lead may be taken";
  EXPECT_LT(last_real_refused, kLead / kPeriod + 1) << "real states refused after the first lead: the lead walked forward";
  EXPECT_GE(real_new, kSteps - kLead / kPeriod - 1);
  EXPECT_GE(f.refusedAhead(), kSteps - 2);
  EXPECT_EQ(f.resyncs(), 0);
}

}  // namespace
}  // namespace masa::deploy
