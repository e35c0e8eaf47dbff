// The actor's adaptive wait for newer parameters.
#include <gtest/gtest.h>

#include "actors/await_budget.hpp"

using masa::actor::AwaitBudget;

TEST(AwaitBudget, WaitsTheConfiguredTimeUntilTheLearnerIsSlowerThenOneAndAHalfItsAnswerTime) {
  AwaitBudget b(1.0, 10.0);
  EXPECT_DOUBLE_EQ(b.limitSeconds(), 1.0);  // nothing measured yet
  b.observeAnswer(0.4);                     // a fast learner: the configured wait stands
  EXPECT_DOUBLE_EQ(b.limitSeconds(), 1.0);
  b.observeAnswer(4.0);                     // moving average 0.7 * 0.4 + 0.3 * 4 = 1.48
  EXPECT_NEAR(b.learnerDelaySeconds(), 1.48, 1e-12);
  EXPECT_NEAR(b.limitSeconds(), 2.22, 1e-12);
  for (int i = 0; i < 40; ++i) b.observeAnswer(4.0);  // settles at 4 s: wait 6 s
  EXPECT_NEAR(b.limitSeconds(), 6.0, 1e-5);
}

TEST(AwaitBudget, IsBoundedAndCanBeSwitchedOff) {
  AwaitBudget b(1.0, 10.0);
  b.observeAnswer(60.0);  // a learner stuck in a long evaluation
  EXPECT_DOUBLE_EQ(b.limitSeconds(), 10.0);
  AwaitBudget off(0.0, 10.0);
  off.observeAnswer(5.0);
  EXPECT_DOUBLE_EQ(off.limitSeconds(), 0.0);
}
