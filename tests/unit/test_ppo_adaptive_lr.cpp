// rl_games' KL-adaptive learning rate.
#include <gtest/gtest.h>

#include <stdexcept>

#include "learner/ppo/adaptive_lr.hpp"

namespace masa::ppo {
namespace {

constexpr double kThreshold = 0.008;

TEST(AdaptiveLr, RaisesByHalfWhenKlIsBelowHalfTheThreshold) {
  AdaptiveLr lr(LrSchedule::kAdaptive, 1e-3, kThreshold, 1e-6, 1e-2);
  EXPECT_DOUBLE_EQ(lr.update(0.49 * kThreshold), 1.5e-3);
  EXPECT_DOUBLE_EQ(lr.lr(), 1.5e-3);
}

TEST(AdaptiveLr, LowersByOneAndAHalfWhenKlIsAboveTwiceTheThreshold) {
  AdaptiveLr lr(LrSchedule::kAdaptive, 1.5e-3, kThreshold, 1e-6, 1e-2);
  EXPECT_DOUBLE_EQ(lr.update(2.01 * kThreshold), 1e-3);
}

TEST(AdaptiveLr, KeepsTheRateInsideTheBand) {
  AdaptiveLr lr(LrSchedule::kAdaptive, 1e-3, kThreshold, 1e-6, 1e-2);
  for (double kl : {0.5 * kThreshold, kThreshold, 2.0 * kThreshold}) EXPECT_DOUBLE_EQ(lr.update(kl), 1e-3) << kl;
}

TEST(AdaptiveLr, ClampsToItsBounds) {
  AdaptiveLr high(LrSchedule::kAdaptive, 8e-3, kThreshold, 1e-6, 1e-2);
  EXPECT_DOUBLE_EQ(high.update(0.0), 1e-2);
  EXPECT_DOUBLE_EQ(high.update(0.0), 1e-2);
  AdaptiveLr low(LrSchedule::kAdaptive, 1.2e-6, kThreshold, 1e-6, 1e-2);
  EXPECT_DOUBLE_EQ(low.update(1.0), 1e-6);
  EXPECT_DOUBLE_EQ(low.update(1.0), 1e-6);
}

TEST(AdaptiveLr, FixedScheduleNeverChanges) {
  AdaptiveLr lr(LrSchedule::kFixed, 5e-4, kThreshold, 1e-6, 1e-2);
  for (double kl : {0.0, 1e-9, kThreshold, 1.0, 100.0}) EXPECT_DOUBLE_EQ(lr.update(kl), 5e-4) << kl;
}

TEST(AdaptiveLr, ParsesScheduleNamesAndRejectsOthers) {
  EXPECT_EQ(parseLrSchedule("adaptive"), LrSchedule::kAdaptive);
  EXPECT_EQ(parseLrSchedule("fixed"), LrSchedule::kFixed);
  EXPECT_THROW(parseLrSchedule("linear"), std::invalid_argument);
}

}  // namespace
}  // namespace masa::ppo
