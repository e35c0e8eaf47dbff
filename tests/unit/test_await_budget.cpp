// The actor's adaptive wait for newer parameters.
#include <gtest/gtest.h>

#include "actors/await_budget.hpp"
#include "actors/policy_lag_window.hpp"

using masa::actor::AwaitBudget;

TEST(AwaitBudget, WaitsTheConfiguredTimeUntilMeasuredThenOneAndAHalfTheLearnersAnswerTime) {
  AwaitBudget b(1.0, 10.0);
  EXPECT_DOUBLE_EQ(b.limitSeconds(), 1.0);  // nothing measured yet: the configured wait
  b.observeAnswer(4.0);                     // a slow learner: longer
  EXPECT_NEAR(b.limitSeconds(), 6.0, 1e-12);
  for (int i = 0; i < 40; ++i) b.observeAnswer(0.04);  // settles at 40 ms: wait 60 ms
  EXPECT_NEAR(b.limitSeconds(), 0.06, 1e-5);
}

// A lost chunk leaves the learner's batch short, and it says nothing: the actors' wait is the
// time the whole run stands still. It follows a fast learner down, to a floor.
TEST(AwaitBudget, AFastLearnersWaitIsShortNotTheConfiguredSecond) {
  AwaitBudget b(1.0, 10.0, 0.02);
  b.observeAnswer(0.03);
  EXPECT_NEAR(b.limitSeconds(), 0.045, 1e-12);
  b.observeAnswer(0.001);  // average 0.0213: 1.5x is 0.032
  EXPECT_NEAR(b.limitSeconds(), 1.5 * (0.7 * 0.03 + 0.3 * 0.001), 1e-12);
  AwaitBudget floor(1.0, 10.0, 0.02);
  floor.observeAnswer(0.001);
  EXPECT_DOUBLE_EQ(floor.limitSeconds(), 0.02);
}

// Before the first answer, a wait that times out doubles the next (the learner's first update may
// outlast the configured second: each actor sent a stale rollout a second until it ended, 1440
// dropped chunks at 15 actors on the 16-core machine); after answers are measured they decide.
TEST(AwaitBudget, BeforeAnyAnswerATimedOutWaitDoublesTheNextUpToTheBound) {
  AwaitBudget b(1.0, 10.0);
  b.observeTimeout();
  EXPECT_DOUBLE_EQ(b.limitSeconds(), 2.0);
  b.observeTimeout();
  b.observeTimeout();
  EXPECT_DOUBLE_EQ(b.limitSeconds(), 8.0);
  b.observeTimeout();
  EXPECT_DOUBLE_EQ(b.limitSeconds(), 10.0) << "the bound";
  b.observeAnswer(0.5);
  EXPECT_NEAR(b.limitSeconds(), 0.75, 1e-12) << "a measured answer sets the wait";
  b.observeTimeout();
  EXPECT_NEAR(b.limitSeconds(), 0.75, 1e-12) << "after answers, a timeout is a loss, not a slow learner";
  AwaitBudget off(0.0, 10.0);
  off.observeTimeout();
  EXPECT_DOUBLE_EQ(off.limitSeconds(), 0.0) << "switched off stays off";
}

TEST(AwaitBudget, IsBoundedAndCanBeSwitchedOff) {
  AwaitBudget b(1.0, 10.0);
  b.observeAnswer(60.0);  // a learner stuck in a long evaluation
  EXPECT_DOUBLE_EQ(b.limitSeconds(), 10.0);
  AwaitBudget off(0.0, 10.0);
  off.observeAnswer(5.0);
  EXPECT_DOUBLE_EQ(off.limitSeconds(), 0.0);
}

using masa::actor::PolicyLagWindow;

// Lag 0: the next rollout needs the answer to the last; an answer is an answer once.
TEST(PolicyLagWindow, LagZeroNeedsTheAnswerToTheLastRollout) {
  PolicyLagWindow w(0);
  EXPECT_EQ(w.neededVersion(), -1) << "nothing sent: nothing needed";
  w.sent(3, 10.0);
  EXPECT_EQ(w.neededVersion(), 4);
  EXPECT_FALSE(w.answer(3, 10.5)) << "the learner's repeat of the version acted with answers nothing";
  const auto delay = w.answer(4, 11.25);
  ASSERT_TRUE(delay);
  EXPECT_DOUBLE_EQ(*delay, 1.25);
  EXPECT_FALSE(w.answer(5, 12.0)) << "already answered";
  w.sent(5, 13.0);
  EXPECT_EQ(w.neededVersion(), 6);
}

// An actor that gave up waiting sends a rollout of the old version (the learner drops it). The
// answer that comes after is timed from the end of the rollout the actor waited on, not from the
// stale one: else a slow learner looks quick, the budget shrinks and every wait times out (found
// on a 16-core machine: 15 actors, one learner core, 1000 dropped rollout chunks per update).
TEST(PolicyLagWindow, AnAnswerAfterAWaitThatTimedOutIsTimedFromTheRolloutWaitedOn) {
  PolicyLagWindow w(0);
  w.sent(0, 1.0);  // waits for update 1 ...
  w.sent(0, 3.0);  // ... gave up at 2.5 s, collected a stale rollout
  const auto delay = w.answer(1, 4.0);
  ASSERT_TRUE(delay);
  EXPECT_DOUBLE_EQ(*delay, 3.0) << "the learner took 3 s since the first rollout's end, not 1 s";
  // With the budget fed these answers, a learner that always takes 3 s is waited for after one miss.
  masa::actor::AwaitBudget budget(1.0, 10.0);
  budget.observeAnswer(*delay);
  EXPECT_GE(budget.limitSeconds(), 3.0);
  // A rollout that was answered leaves no trace on the next one's time.
  w.sent(1, 5.0);
  const auto next = w.answer(2, 5.5);
  ASSERT_TRUE(next);
  EXPECT_DOUBLE_EQ(*next, 0.5);
}

// Lag 1: one rollout may be unanswered when the next starts; the update that takes a rollout
// comes after the one that takes the rollout before it.
TEST(PolicyLagWindow, LagOneLetsOneRolloutBeUnansweredAndCountsTheUpdatesBeforeItsAnswer) {
  PolicyLagWindow w(1);
  w.sent(0, 1.0);  // answered by update 1
  EXPECT_EQ(w.neededVersion(), -1) << "the second rollout goes ahead while the first is learned from";
  w.sent(0, 2.0);  // acted with 0 too, but taken after the first: answered by update 2
  EXPECT_EQ(w.neededVersion(), 1) << "the third needs the answer to the first";
  const auto first = w.answer(1, 2.5);
  ASSERT_TRUE(first);
  EXPECT_DOUBLE_EQ(*first, 1.5) << "from the end of the first rollout";
  w.sent(1, 3.0);  // the third, acted with version 1, taken after the second: update 3
  EXPECT_EQ(w.neededVersion(), 2) << "the fourth needs update 2 (it takes the second rollout), not just any version above 0";
  EXPECT_FALSE(w.answer(1, 3.2)) << "a repeat answers nothing";
  const auto second = w.answer(2, 3.5);
  ASSERT_TRUE(second);
  EXPECT_DOUBLE_EQ(*second, 1.5) << "the second rollout's, ended at 2.0";
  // Steady state: every rollout acted with the answer to the one two before it arrives one
  // version behind the learner, within the lag.
  w.sent(2, 4.0);
  EXPECT_EQ(w.neededVersion(), 3);
  EXPECT_THROW(PolicyLagWindow(-1), std::invalid_argument);
}
