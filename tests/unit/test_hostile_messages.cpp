// Hostile bytes on every channel, through the path every process uses (Transport::subscribe over
// an in-process memq:// LCM): crafted lengths, truncated and overlong copies of real messages,
// and a bounded mutation fuzz. Nothing may crash, allocate without bound, or be delivered unless
// it is exactly a message the encoder could have written.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "actors/rollout_chunker.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/message_mutator.hpp"
#include "common/transport/transport.hpp"
#include "masa/lcmt_actor_heartbeat.hpp"
#include "masa/lcmt_learner_stats.hpp"
#include "masa/lcmt_policy_params.hpp"
#include "masa/lcmt_rollout_chunk.hpp"
#include "test_transport_support.hpp"

namespace masa::transport {
namespace {

// The actors' chunking and the learner's intake, tested against each other and the wire.
using namespace masa::actor;
using namespace masa::learner;

using testing::encode;
using testing::samplePolicy;

masa::lcmt_actor_heartbeat sampleHeartbeat() {
  masa::lcmt_actor_heartbeat h{};
  h.run_id = 42;
  h.actor_id = 1;
  h.utime = 1'700'000'000'000'000;
  h.hostname = "node-3";
  h.num_envs = 16;
  h.steps_per_second = 1234.5f;
  h.policy_version = 17;
  h.rollouts_sent = 9;
  return h;
}

masa::lcmt_learner_stats sampleStats() {
  masa::lcmt_learner_stats s{};
  s.run_id = 42;
  s.utime = 1'700'000'000'000'000;
  s.update = 17;
  s.env_steps = 1 << 20;
  s.fps = 5000.0f;
  s.num_episodes = 3;
  s.drop_reason_names = {"malformed", "wrong_run", "too_old"};
  s.drop_counts = {1, 2, 3};
  s.num_drop_reasons = 3;
  s.term_names = {"velocity", "alive"};
  s.term_means = {1.5f, 0.25f};
  s.num_terms = 2;
  return s;
}

// A small real chunk, with truncations, episodes and term names (every array non-empty).
masa::lcmt_rollout_chunk sampleChunk() {
  rollout::Rollout r;
  testing::fillRandomRollout(r, testing::RolloutShape{3, 4, 5, 2}, 9, 0.3);
  RolloutChunker chunker(1 << 20);
  const auto chunks = chunker.split(r, RolloutIdentity{.run_id = 42, .actor_id = 1, .rollout_seq = 5, .policy_version = 17});
  EXPECT_EQ(chunks.size(), 1u);
  EXPECT_GT(chunks[0].num_final, 0);
  EXPECT_GT(chunks[0].num_episodes, 0);
  return chunks[0];
}

// Publishes raw bytes on `channel` and counts what the typed subscription delivers; every
// delivered message must re-encode to exactly the bytes that were sent.
template <class Msg>
struct Receiver {
  explicit Receiver(const char* channel) : channel(channel), bus("memq://") {
    bus.subscribe<Msg>(channel, [this](const Msg& m) {
      ++delivered;
      if (encode(m) != sent) ++not_reencoded;
    });
  }
  void send(const std::vector<uint8_t>& bytes) {
    sent = bytes;
    ASSERT_TRUE(bus.publishRaw(channel, bytes.data(), static_cast<int>(bytes.size())));
    bus.drain();
    ++published;
  }
  const char* channel;
  Transport bus;
  std::vector<uint8_t> sent;
  int64_t published = 0, delivered = 0, not_reencoded = 0;
};

void putBigEndian32(std::vector<uint8_t>& b, std::size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = static_cast<uint8_t>(v >> (24 - 8 * i));
}

// The message: a policy header whose num_params is 0x7f7fffff, 77 bytes in all. lcm-gen's
// decoder computes 4 * num_params in an int; it overflowed and the decoder read far past the bytes.
std::vector<uint8_t> craftedPolicy(uint32_t num_params) {
  masa::lcmt_policy_params p{};
  p.run_id = 42;
  p.version = 3;
  p.method = "masa";
  p.task = "a1_beam";
  p.num_params = 5;
  p.params.assign(5, 1.0f);
  std::vector<uint8_t> bytes = encode(p);  // 8 + 24 + 9 + 12 + 4 + 20 + 4 = 81
  bytes.resize(77);                        // cut inside obs_dim, as the crafted one was
  putBigEndian32(bytes, 8 + 24 + 9 + 12, num_params);
  return bytes;
}

TEST(HostileMessages, CraftedPolicyMessageWithAnOverflowingNumParamsIsRejectedWithoutCrashing) {
  Receiver<masa::lcmt_policy_params> rx(kPolicyChannel);
  for (uint32_t n : {0x7f7fffffu, 0x20000000u, 0x40000001u, 0xffffffffu, 0x80000000u}) {
    const std::vector<uint8_t> bytes = craftedPolicy(n);
    ASSERT_EQ(bytes.size(), 77u);
    rx.send(bytes);
  }
  EXPECT_EQ(rx.delivered, 0);
  EXPECT_EQ(rx.bus.decodeErrors(), rx.published);
}

// Every proper prefix and a few extensions of a real message: none is delivered, each is counted.
template <class Msg>
void expectCutsAndExtensionsRejected(const Msg& real, const char* channel) {
  Receiver<Msg> rx(channel);
  const std::vector<uint8_t> bytes = encode(real);
  rx.send(bytes);
  ASSERT_EQ(rx.delivered, 1) << "the intact message is delivered";
  for (std::size_t cut = 0; cut < bytes.size(); ++cut)
    rx.send(std::vector<uint8_t>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(cut)));
  for (int extra = 1; extra <= 8; ++extra) {
    std::vector<uint8_t> longer = bytes;
    longer.insert(longer.end(), extra, static_cast<uint8_t>(extra));
    rx.send(longer);
  }
  EXPECT_EQ(rx.delivered, 1) << channel;
  EXPECT_EQ(rx.bus.decodeErrors(), rx.published - 1) << channel;
}

TEST(HostileMessages, TruncatedAndOverlongCopiesOfRealMessagesOfEveryTypeAreRejected) {
  expectCutsAndExtensionsRejected(samplePolicy(), kPolicyChannel);
  expectCutsAndExtensionsRejected(sampleHeartbeat(), kHeartbeatChannel);
  expectCutsAndExtensionsRejected(sampleStats(), kLearnerStatsChannel);
  expectCutsAndExtensionsRejected(sampleChunk(), kRolloutChannel);
}

template <class Msg>
void fuzz(const Msg& real, const char* channel, int copies, uint64_t seed) {
  Receiver<Msg> rx(channel);
  MessageMutator mutator(encode(real), seed);
  for (int i = 0; i < copies; ++i) rx.send(mutator.next());
  EXPECT_EQ(rx.published, copies);
  EXPECT_EQ(rx.delivered + rx.bus.decodeErrors(), rx.published) << channel << ": every copy delivered or counted";
  EXPECT_EQ(rx.not_reencoded, 0) << channel << ": a delivered message must re-encode to the bytes received";
  EXPECT_GT(rx.bus.decodeErrors(), copies / 2) << channel << ": most mutations are invalid";
  std::printf("fuzz %s: %d mutated copies, %lld delivered (valid re-encodings), %lld rejected\n", channel, copies,
              static_cast<long long>(rx.delivered), static_cast<long long>(rx.bus.decodeErrors()));
}

TEST(HostileMessages, MutationFuzzOfEveryMessageTypeNeverCrashesAndDeliversOnlyValidMessages) {
  constexpr int kCopies = 20000;
  fuzz(samplePolicy(), kPolicyChannel, kCopies, 1);
  fuzz(sampleHeartbeat(), kHeartbeatChannel, kCopies, 2);
  fuzz(sampleStats(), kLearnerStatsChannel, kCopies, 3);
  fuzz(sampleChunk(), kRolloutChannel, kCopies, 4);
}

}  // namespace
}  // namespace masa::transport
