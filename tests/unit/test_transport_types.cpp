#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <optional>

#include "common/transport/channels.hpp"
#include "common/transport/lcm_url.hpp"
#include "common/transport/transport.hpp"
#include "masa/lcmt_actor_heartbeat.hpp"
#include "masa/lcmt_learner_stats.hpp"
#include "masa/lcmt_policy_params.hpp"
#include "masa/lcmt_rollout_chunk.hpp"
#include "test_transport_support.hpp"

namespace masa::transport {
namespace {

using testing::encode;

// Publishes `sent` on an in-process memq:// transport and returns what the subscriber decoded.
template <class Msg>
std::optional<Msg> roundTrip(const Msg& sent, const char* channel) {
  Transport t("memq://");
  std::optional<Msg> got;
  t.subscribe<Msg>(channel, [&](const Msg& m) { got = m; });
  EXPECT_TRUE(t.publish(channel, sent));
  for (int i = 0; i < 10 && !got; ++i) t.handleTimeout(100);
  return got;
}

TEST(TransportTypes, RolloutChunkSurvivesMemqRoundTrip) {
  masa::lcmt_rollout_chunk c{};
  c.run_id = 0x1234567890ll;
  c.actor_id = 3;
  c.rollout_seq = 77;
  c.chunk_index = 1;
  c.num_chunks = 2;
  c.policy_version = 9;
  c.horizon = 2;
  c.obs_dim = 3;
  c.act_dim = 1;
  c.num_envs = 1;
  c.env_offset = 5;
  c.obs = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  c.obs_len = 9;
  c.actions = {0.5f, -0.5f};
  c.mean = {0.25f, -0.25f};
  c.act_len = 2;
  c.log_prob = {-1, -2};
  c.reward = {0.1f, 0.2f};
  c.terminated = {0, 0};
  c.truncated = {0, 1};
  c.step_len = 2;
  c.log_std = {-0.7f};
  c.log_std_len = 1;
  c.final_index = {1};
  c.num_final = 1;
  c.final_obs = {10, 11, 12};
  c.final_obs_len = 3;
  c.episode_env = {5};
  c.episode_return = {42.5f};
  c.episode_length = {100};
  c.episode_success = {-1};
  c.num_episodes = 1;
  c.term_names = {"alive", "velocity"};
  c.num_terms = 2;
  c.episode_term_sums = {1.5f, 2.5f};
  c.term_sums_len = 2;
  const auto got = roundTrip(c, kRolloutChannel);
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(encode(*got), encode(c));
  EXPECT_EQ(got->run_id, c.run_id);
  EXPECT_EQ(got->final_obs, c.final_obs);
  EXPECT_EQ(got->term_names, c.term_names);
}

TEST(TransportTypes, PolicyParamsSurviveMemqRoundTrip) {
  masa::lcmt_policy_params p{};
  p.run_id = 11;
  p.utime = wallClockMicros();
  p.version = 4;
  p.method = "masa";
  p.task = "humanoid_tightrope";
  p.params = {0.1f, -0.2f, 0.3f, 1e-8f};
  p.num_params = 4;
  p.obs_mean = {0.0f, 1.0f};
  p.obs_std = {1.0f, 2.0f};
  p.obs_dim = 2;
  const auto got = roundTrip(p, kPolicyChannel);
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(encode(*got), encode(p));
  EXPECT_EQ(got->params, p.params);
  EXPECT_EQ(got->task, p.task);
}

TEST(TransportTypes, LearnerStatsSurviveMemqRoundTrip) {
  masa::lcmt_learner_stats s{};
  s.run_id = 11;
  s.utime = 123456;
  s.update = 8;
  s.env_steps = 1ll << 40;
  s.fps = 61234.5f;
  s.mean_episode_return = 12.5f;
  s.mean_episode_length = 300;
  s.success_rate = -1;
  s.num_episodes = 17;
  s.actor_loss = 0.1f;
  s.critic_loss = 0.2f;
  s.entropy = 0.3f;
  s.bounds_loss = 0.4f;
  s.symmetry_policy_loss = 0.5f;
  s.symmetry_value_loss = 0.6f;
  s.kl = 0.007f;
  s.learning_rate = 5e-4f;
  s.grad_norm = 0.9f;
  s.explained_variance = 0.8f;
  s.drop_reason_names = {"wrong_run", "too_old"};
  s.drop_counts = {3, 1ll << 33};
  s.num_drop_reasons = 2;
  s.term_names = {"alive"};
  s.term_means = {4.0f};
  s.num_terms = 1;
  const auto got = roundTrip(s, kLearnerStatsChannel);
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(encode(*got), encode(s));
  EXPECT_EQ(got->drop_counts, s.drop_counts);
}

TEST(TransportTypes, ActorHeartbeatSurvivesMemqRoundTrip) {
  masa::lcmt_actor_heartbeat h{};
  h.run_id = 11;
  h.actor_id = 2;
  h.utime = 99;
  h.hostname = "node-7";
  h.num_envs = 512;
  h.steps_per_second = 30000.5f;
  h.policy_version = -1;
  h.rollouts_sent = 12;
  const auto got = roundTrip(h, kHeartbeatChannel);
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(encode(*got), encode(h));
  EXPECT_EQ(got->hostname, "node-7");
}

TEST(TransportTypes, UndecodableBytesAreCountedNotDelivered) {
  Transport t("memq://");
  int delivered = 0;
  t.subscribe<masa::lcmt_actor_heartbeat>(kHeartbeatChannel, [&](const masa::lcmt_actor_heartbeat&) { ++delivered; });
  const uint8_t junk[5] = {1, 2, 3, 4, 5};
  ASSERT_TRUE(t.publishRaw(kHeartbeatChannel, junk, sizeof junk));
  t.handleTimeout(100);
  EXPECT_EQ(delivered, 0);
  EXPECT_EQ(t.decodeErrors(), 1);
}

TEST(TransportUrl, LoopbackAndLanUrlsAskForTheBigReceiveBuffer) {
  EXPECT_EQ(loopbackUrl(), "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608");
  EXPECT_EQ(lanUrl(), "udpm://239.255.76.67:7667?ttl=1&recv_buf_size=8388608");
  EXPECT_EQ(recvBufSizeOf(loopbackUrl(4194304)), 4194304);
  EXPECT_EQ(recvBufSizeOf("udpm://239.255.76.67:7667?ttl=0"), -1);
  EXPECT_EQ(recvBufSizeOf("memq://"), -1);
}

TEST(TransportUrl, ReceiveBufferCheckWarnsWhenRmemMaxIsSmaller) {
  const std::string path = ::testing::TempDir() + "masa_rmem_max_test";
  {
    std::ofstream(path) << "4194304\n";
  }
  const RecvBufCheck small = checkRecvBuf(8388608, path);
  EXPECT_FALSE(small.sufficient);
  EXPECT_EQ(small.rmem_max, 4194304);
  EXPECT_NE(small.message.find("rmem_max"), std::string::npos);
  const RecvBufCheck enough = checkRecvBuf(4194304, path);
  EXPECT_TRUE(enough.sufficient);
  EXPECT_TRUE(enough.message.empty());
  const RecvBufCheck unknown = checkRecvBuf(8388608, path + ".missing");
  EXPECT_TRUE(unknown.sufficient);  // cannot tell: no warning
  EXPECT_EQ(unknown.rmem_max, -1);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace masa::transport
