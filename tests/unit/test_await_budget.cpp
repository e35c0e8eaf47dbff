// The actor's adaptive wait for newer parameters.
#include <gtest/gtest.h>

#include "actors/await_budget.hpp"

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

TEST(AwaitBudget, IsBoundedAndCanBeSwitchedOff) {
  AwaitBudget b(1.0, 10.0);
  b.observeAnswer(60.0);  // a learner stuck in a long evaluation
  EXPECT_DOUBLE_EQ(b.limitSeconds(), 10.0);
  AwaitBudget off(0.0, 10.0);
  off.observeAnswer(5.0);
  EXPECT_DOUBLE_EQ(off.limitSeconds(), 0.0);
}
