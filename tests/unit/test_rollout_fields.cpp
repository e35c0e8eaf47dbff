// The rollout's one list of fields and the copy of environments made from it
// (common/rollout/rollout_fields.hpp): every value lands at its mapped environment, events follow
// their environment and are renumbered, and nothing else is touched.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "common/rollout/rollout.hpp"
#include "common/rollout/rollout_fields.hpp"

namespace masa::rollout {
namespace {

constexpr int kRolloutT = 3, kObs = 2, kAct = 2;

// A rollout of `envs` environments whose every value says where it is: value(field, t, e, k).
Rollout filled(int envs, int terms) {
  std::vector<std::string> names;
  for (int k = 0; k < terms; ++k) names.push_back("term" + std::to_string(k));
  Rollout r;
  r.allocate(envs, kRolloutT, kObs, kAct, names);
  for (int t = 0; t <= kRolloutT; ++t)
    for (int e = 0; e < envs; ++e)
      for (int k = 0; k < kObs; ++k) r.obsAt(t, e)[k] = 1000.0f * t + 10.0f * e + k;
  for (int t = 0; t < kRolloutT; ++t)
    for (int e = 0; e < envs; ++e) {
      for (int k = 0; k < kAct; ++k) {
        r.actionAt(t, e)[k] = 2000.0f + 1000.0f * t + 10.0f * e + k;
        r.meanAt(t, e)[k] = -2000.0f - 1000.0f * t - 10.0f * e - k;
      }
      r.log_prob[r.step(t, e)] = 0.5f * t + 0.01f * e;
      r.reward[r.step(t, e)] = 7.0f * t + e;
      r.terminated[r.step(t, e)] = (t + e) % 2;
      r.truncated[r.step(t, e)] = (t * e) % 3 == 1;
    }
  // Truncations at (0, 1), (1, 3), (2, 0), (2, 4); episodes of environments 4, 1 and 3.
  const float fo[4][kObs] = {{1, 2}, {3, 4}, {5, 6}, {7, 8}};
  const int at[4][2] = {{0, 1}, {1, 3}, {2, 0}, {2, 4}};
  for (int i = 0; i < 4; ++i)
    if (at[i][1] < envs) r.addFinal(at[i][0], at[i][1], fo[i]);
  std::vector<float> sums(terms);
  for (int e : {4, 1, 3}) {
    if (e >= envs) continue;
    for (int k = 0; k < terms; ++k) sums[k] = 100.0f * e + k;
    r.addEpisode(e, 1.5f * e, 10 + e, static_cast<int8_t>(e % 2), terms ? sums.data() : nullptr);
  }
  return r;
}

TEST(RolloutFields, EnvironmentsLandAtTheirMappedColumnsWithTheirEventsRenumbered) {
  const Rollout src = filled(5, 2);
  Rollout dst;
  dst.allocate(3, kRolloutT, kObs, kAct, src.term_names);
  std::fill(dst.obs.begin(), dst.obs.end(), -1.0f);
  const std::vector<int> to = {-1, 2, 0, 1, -1};  // source env 1 -> 2, 2 -> 0, 3 -> 1
  const EnvCopy copy{.horizon = kRolloutT, .obs_dim = kObs, .act_dim = kAct, .src_envs = 5, .dst_envs = 3, .dst_env = to,
                     .src_terms = 2, .dst_terms = 2};
  copyEnvironmentSteps(src, dst, copy);
  appendEnvironmentEvents(src, dst, copy);

  for (int e = 0; e < 5; ++e) {
    const int d = to[e];
    if (d < 0) continue;
    for (int t = 0; t <= kRolloutT; ++t)
      for (int k = 0; k < kObs; ++k) EXPECT_EQ(dst.obsAt(t, d)[k], src.obsAt(t, e)[k]) << t << " " << e;
    for (int t = 0; t < kRolloutT; ++t) {
      for (int k = 0; k < kAct; ++k) {
        EXPECT_EQ(dst.actionAt(t, d)[k], src.actionAt(t, e)[k]);
        EXPECT_EQ(dst.meanAt(t, d)[k], src.meanAt(t, e)[k]);
      }
      EXPECT_EQ(dst.log_prob[dst.step(t, d)], src.log_prob[src.step(t, e)]);
      EXPECT_EQ(dst.reward[dst.step(t, d)], src.reward[src.step(t, e)]);
      EXPECT_EQ(dst.terminated[dst.step(t, d)], src.terminated[src.step(t, e)]);
      EXPECT_EQ(dst.truncated[dst.step(t, d)], src.truncated[src.step(t, e)]);
    }
  }
  // Truncations of source environments 1 and 3 only: (0, 1) -> (0, 2), (1, 3) -> (1, 1).
  EXPECT_EQ(dst.final_index, (std::vector<int32_t>{0 * 3 + 2, 1 * 3 + 1}));
  EXPECT_EQ(dst.final_obs, (std::vector<float>{1, 2, 3, 4}));
  // Episodes of 1 and 3 (4 is left out), in the source's order.
  EXPECT_EQ(dst.episode_env, (std::vector<int32_t>{2, 1}));
  EXPECT_EQ(dst.episode_return, (std::vector<float>{1.5f, 4.5f}));
  EXPECT_EQ(dst.episode_length, (std::vector<int32_t>{11, 13}));
  EXPECT_EQ(dst.episode_success, (std::vector<int8_t>{1, 1}));
  EXPECT_EQ(dst.episode_term_sums, (std::vector<float>{100, 101, 300, 301}));
}

// A chunk numbers its episodes' environments from its env_offset; a source with other reward
// terms keeps its returns and leaves the destination's term sums at zero.
TEST(RolloutFields, EpisodeNumberingBasesAndOtherTermsAreHonoured) {
  const Rollout src = filled(5, 3);
  Rollout dst;
  dst.allocate(2, kRolloutT, kObs, kAct, {"a", "b"});
  const std::vector<int> to = {-1, -1, -1, 0, 1};
  const EnvCopy copy{.horizon = kRolloutT, .obs_dim = kObs, .act_dim = kAct, .src_envs = 5, .dst_envs = 2, .dst_env = to,
                     .src_episode_base = 0, .dst_episode_base = 10, .src_terms = 3, .dst_terms = 2};
  appendEnvironmentEvents(src, dst, copy);
  EXPECT_EQ(dst.episode_env, (std::vector<int32_t>{11, 10}));  // source 4 -> 1, 3 -> 0, from base 10
  EXPECT_EQ(dst.episode_return, (std::vector<float>{6.0f, 4.5f}));
  EXPECT_EQ(dst.episode_term_sums, (std::vector<float>(4, 0.0f)));

  // And back: a source that numbers from 10.
  Rollout back;
  back.allocate(5, kRolloutT, kObs, kAct, {"a", "b"});
  const std::vector<int> from_chunk = {3, 4};
  const EnvCopy copy_back{.horizon = kRolloutT, .obs_dim = kObs, .act_dim = kAct, .src_envs = 2, .dst_envs = 5,
                          .dst_env = from_chunk, .src_episode_base = 10, .src_terms = 2, .dst_terms = 2};
  appendEnvironmentEvents(dst, back, copy_back);
  EXPECT_EQ(back.episode_env, (std::vector<int32_t>{4, 3}));
}

TEST(RolloutFields, SortFinalsPutsTruncationsInStepOrderWithTheirObservations) {
  Rollout r;
  r.allocate(2, kRolloutT, kObs, kAct);
  r.final_index = {5, 1, 3};
  r.final_obs = {50, 51, 10, 11, 30, 31};
  std::vector<std::pair<int32_t, int32_t>> order;
  std::vector<float> scratch;
  sortFinals(r, kObs, order, scratch);
  EXPECT_EQ(r.final_index, (std::vector<int32_t>{1, 3, 5}));
  EXPECT_EQ(r.final_obs, (std::vector<float>{10, 11, 30, 31, 50, 51}));
}

TEST(RolloutFields, ResizeAndClearWalkEveryArray) {
  Rollout r = filled(4, 1);
  resizeSteps(r, kRolloutT, 2, kObs, kAct);
  EXPECT_EQ(r.obs.size(), static_cast<std::size_t>((kRolloutT + 1) * 2 * kObs));
  EXPECT_EQ(r.actions.size(), static_cast<std::size_t>(kRolloutT * 2 * kAct));
  EXPECT_EQ(r.mean.size(), r.actions.size());
  for (const std::size_t n : {r.log_prob.size(), r.reward.size(), r.terminated.size(), r.truncated.size()})
    EXPECT_EQ(n, static_cast<std::size_t>(kRolloutT * 2));
  clearEvents(r);
  EXPECT_EQ(r.numFinal(), 0);
  EXPECT_TRUE(r.final_obs.empty());
  EXPECT_EQ(r.numEpisodes(), 0);
  EXPECT_TRUE(r.episode_return.empty() && r.episode_length.empty() && r.episode_success.empty() &&
              r.episode_term_sums.empty());
}

}  // namespace
}  // namespace masa::rollout
