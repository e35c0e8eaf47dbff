// RunningMeanStd::setMeanStd, which the actor uses to install the learner's broadcast statistics.
#include <gtest/gtest.h>

#include "common/model/running_mean_std.hpp"

namespace masa {
namespace {

TEST(ActorNormalizer, SetMeanStdNormalizesWithExactlyTheBroadcastValues) {
  model::RunningMeanStd<float> n(2);
  const float mean[2] = {1.0f, -2.0f};
  const float sd[2] = {2.0f, 0.5f};
  n.setMeanStd(mean, sd);
  Mat<float> x(2, 1), y(2, 1);
  x << 3.0f, -1.0f;
  n.normalize(x, y);
  EXPECT_FLOAT_EQ(y(0, 0), 1.0f);
  EXPECT_FLOAT_EQ(y(1, 0), 2.0f);
  EXPECT_DOUBLE_EQ(n.mean()(1), -2.0);
}

TEST(ActorNormalizer, SetMeanStdRejectsNonPositiveStd) {
  model::RunningMeanStd<float> n(1);
  const float mean[1] = {0.0f};
  const float sd[1] = {0.0f};
  EXPECT_ANY_THROW(n.setMeanStd(mean, sd));
}

}  // namespace
}  // namespace masa
