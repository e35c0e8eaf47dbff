// The strip's frame choice: evenly over the whole episode, however short or long, in bounded memory.
#include <gtest/gtest.h>

#include "common/render/strip_sampler.hpp"

namespace masa::render {
namespace {

std::vector<int> sampleEpisode(int frames, int length) {
  StripSampler s(frames);
  for (int t = 0; t < length; ++t) {
    if (s.wants(t))
      s.add(t, StripSampler::Image{static_cast<unsigned char>(t % 256)});
    else if (t + 1 == length)
      s.addLast(t, StripSampler::Image{static_cast<unsigned char>(t % 256)});
  }
  return s.pickedSteps();
}

TEST(StripSampler, ATenStepEpisodeFillsAnEightFrameStripWithDistinctStepsFirstAndLastIncluded) {
  const std::vector<int> steps = sampleEpisode(8, 10);
  ASSERT_EQ(steps.size(), 8u);
  EXPECT_EQ(steps.front(), 0);
  EXPECT_EQ(steps.back(), 9);
  for (size_t i = 1; i < steps.size(); ++i) EXPECT_LT(steps[i - 1], steps[i]);
}

TEST(StripSampler, AnEpisodeShorterThanTheStripShowsEveryStep) {
  EXPECT_EQ(sampleEpisode(8, 3), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(sampleEpisode(8, 1), (std::vector<int>{0}));
}

TEST(StripSampler, ALongEpisodeIsSpreadEvenlyToItsEnd) {
  const std::vector<int> steps = sampleEpisode(8, 1000);
  ASSERT_EQ(steps.size(), 8u);
  EXPECT_EQ(steps.front(), 0);
  EXPECT_EQ(steps.back(), 999);
  // Evenly: gaps within a factor of 2 of the ideal 999 / 7.
  for (size_t i = 1; i < steps.size(); ++i) {
    const int gap = steps[i] - steps[i - 1];
    EXPECT_GT(gap, 999 / 7 / 2);
    EXPECT_LT(gap, 999 / 7 * 2);
  }
}

TEST(StripSampler, NeverAsksForMoreThanAboutFourTimesTheFramesOfALongEpisode) {
  StripSampler s(8);
  int rendered = 0;
  for (int t = 0; t < 100000; ++t)
    if (s.wants(t)) {
      s.add(t, StripSampler::Image(1));
      ++rendered;
    }
  // Strides double: 16 at stride 1, then 8 more per doubling (log2(100000 / 16) ~ 13 doublings).
  EXPECT_LT(rendered, 16 + 8 * 14);
}

}  // namespace
}  // namespace masa::render
