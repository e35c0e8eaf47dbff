// The wire guard itself: its tables against lcm-gen's own type hashes, and a named reason for
// each kind of hostile length, counted per channel by the transport.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "common/transport/channels.hpp"
#include "common/transport/transport.hpp"
#include "common/transport/wire_guard.hpp"
#include "masa/lcmt_actor_heartbeat.hpp"
#include "masa/lcmt_learner_stats.hpp"
#include "masa/lcmt_policy_params.hpp"
#include "masa/lcmt_robot_command.hpp"
#include "masa/lcmt_transitions.hpp"
#include "masa/lcmt_robot_state.hpp"
#include "masa/lcmt_rollout_chunk.hpp"
#include "test_transport_support.hpp"

namespace masa::transport {
namespace {

using testing::encode;

// lcm-gen's type fingerprint, recomputed from a WireLayoutOf table: member names, primitive type
// names and dimensions, in order (lcmgen.c, lcm_struct_hash), then rotated left by one bit as the
// generated _computeHash does.
int64_t hashStep(int64_t v, int8_t c) {
  const uint64_t u = static_cast<uint64_t>(v);
  return static_cast<int64_t>(((u << 8) ^ static_cast<uint64_t>(v >> 55)) + static_cast<uint64_t>(int64_t{c}));
}
int64_t hashString(int64_t v, std::string_view s) {
  v = hashStep(v, static_cast<int8_t>(s.size()));
  for (char c : s) v = hashStep(v, static_cast<int8_t>(c));
  return v;
}
std::string_view lcmTypeName(WireType t) {
  switch (t) {
    case WireType::kInt8: return "int8_t";
    case WireType::kInt16: return "int16_t";
    case WireType::kInt32: return "int32_t";
    case WireType::kInt64: return "int64_t";
    case WireType::kFloat: return "float";
    case WireType::kDouble: return "double";
    case WireType::kByte: return "byte";
    case WireType::kBoolean: return "boolean";
    case WireType::kString: return "string";
  }
  return "";
}
template <class Msg>
int64_t lcmHashOfTable() {
  int64_t v = 0x12345678;
  for (const WireField& f : WireLayoutOf<Msg>::fields) {
    v = hashString(v, f.name);
    v = hashString(v, lcmTypeName(f.type));
    if (f.length.empty()) {
      v = hashStep(v, 0);  // no dimensions
    } else {
      v = hashStep(v, 1);  // one dimension,
      v = hashStep(v, 1);  // variable (LCM_VAR),
      v = hashString(v, f.length);  // sized by this field
    }
  }
  const auto u = static_cast<uint64_t>(v);
  return static_cast<int64_t>((u << 1) + ((u >> 63) & 1));
}

TEST(WireGuard, EveryLayoutTableMatchesLcmGensTypeHash) {
  EXPECT_EQ(lcmHashOfTable<masa::lcmt_policy_params>(), masa::lcmt_policy_params::getHash());
  EXPECT_EQ(lcmHashOfTable<masa::lcmt_actor_heartbeat>(), masa::lcmt_actor_heartbeat::getHash());
  EXPECT_EQ(lcmHashOfTable<masa::lcmt_learner_stats>(), masa::lcmt_learner_stats::getHash());
  EXPECT_EQ(lcmHashOfTable<masa::lcmt_rollout_chunk>(), masa::lcmt_rollout_chunk::getHash());
  EXPECT_EQ(lcmHashOfTable<masa::lcmt_robot_state>(), masa::lcmt_robot_state::getHash());
  EXPECT_EQ(lcmHashOfTable<masa::lcmt_robot_command>(), masa::lcmt_robot_command::getHash());
  EXPECT_EQ(lcmHashOfTable<masa::lcmt_transitions>(), masa::lcmt_transitions::getHash());
}

TEST(WireGuard, ATableWhoseLengthNamesNoEarlierIntegerFieldIsRefused) {
  const WireField later[] = {{"values", WireType::kFloat, "n"}, {"n", WireType::kInt32}};
  EXPECT_THROW(WireGuard(1, later), std::logic_error);
  const WireField by_float[] = {{"n", WireType::kFloat}, {"values", WireType::kFloat, "n"}};
  EXPECT_THROW(WireGuard(1, by_float), std::logic_error);
}

masa::lcmt_policy_params policy() {
  masa::lcmt_policy_params p{};
  p.run_id = 42;
  p.version = 3;
  p.method = "masa";
  p.task = "a1_beam";
  p.num_params = 3;
  p.params = {1.0f, 2.0f, 3.0f};
  p.obs_dim = 1;
  p.obs_mean = {0.0f};
  p.obs_std = {1.0f};
  return p;
}

// Offsets in policy()'s encoding: hash 8, run_id/utime/version 24, method 4 + 5, task 4 + 8.
constexpr std::size_t kMethodLen = 32, kTaskLen = 41, kNumParams = 53;

void put32(std::vector<uint8_t>& b, std::size_t at, uint32_t v) {
  ASSERT_LE(at + 4, b.size());
  const uint8_t big_endian[4] = {static_cast<uint8_t>(v >> 24), static_cast<uint8_t>(v >> 16),
                                 static_cast<uint8_t>(v >> 8), static_cast<uint8_t>(v)};
  std::memcpy(b.data() + at, big_endian, 4);
}

WireVerdict verdict(const std::vector<uint8_t>& b) {
  return checkWire<masa::lcmt_policy_params>(b.data(), static_cast<int>(b.size()));
}

TEST(WireGuard, EachKindOfHostileLengthHasItsReason) {
  const std::vector<uint8_t> good = encode(policy());
  ASSERT_EQ(good[kNumParams + 3], 3) << "offsets of the test message";
  EXPECT_EQ(verdict(good), WireVerdict::kOk);
  auto with = [&](std::size_t at, uint32_t v) {
    std::vector<uint8_t> b = good;
    put32(b, at, v);
    return verdict(b);
  };
  EXPECT_EQ(with(kNumParams, 0x7f7fffff), WireVerdict::kOverLimit);
  EXPECT_EQ(with(kNumParams, 0x80000000), WireVerdict::kNegativeLength);
  EXPECT_EQ(with(kNumParams, 100), WireVerdict::kTruncated);
  std::vector<uint8_t> longer = good;
  longer.push_back(0);
  EXPECT_EQ(verdict(longer), WireVerdict::kTrailingBytes);
  EXPECT_EQ(with(kMethodLen, 0), WireVerdict::kBadString) << "length 0: the decoder would take SIZE_MAX characters";
  EXPECT_EQ(with(kMethodLen, 0xffffffff), WireVerdict::kNegativeLength);
  EXPECT_EQ(with(kTaskLen, 5000), WireVerdict::kOverLimit);
  std::vector<uint8_t> no_nul = good;
  no_nul[kMethodLen + 4 + 4] = 'x';  // "masa" followed by 'x' instead of its NUL
  EXPECT_EQ(verdict(no_nul), WireVerdict::kBadString);
  std::vector<uint8_t> inner_nul = good;
  inner_nul[kMethodLen + 4 + 1] = 0;  // "m\0sa": would decode, then re-encode as "m"
  EXPECT_EQ(verdict(inner_nul), WireVerdict::kBadString);
  std::vector<uint8_t> other_type = good;
  other_type[0] ^= 1;
  EXPECT_EQ(verdict(other_type), WireVerdict::kWrongType);
  EXPECT_EQ(checkWire<masa::lcmt_policy_params>(nullptr, 0), WireVerdict::kTruncated);
  // A heartbeat's bytes are no policy message.
  masa::lcmt_actor_heartbeat hb{};
  hb.hostname = "h";
  const std::vector<uint8_t> hb_bytes = encode(hb);
  EXPECT_EQ(verdict(hb_bytes), WireVerdict::kWrongType);
  EXPECT_EQ(checkWire<masa::lcmt_actor_heartbeat>(hb_bytes.data(), static_cast<int>(hb_bytes.size())), WireVerdict::kOk);
}

TEST(WireGuard, TheTransportCountsEveryRejectedMessagePerChannelUnderItsReason) {
  Transport t("memq://");
  int policies = 0, heartbeats = 0;
  t.subscribe<masa::lcmt_policy_params>(kPolicyChannel, [&](const masa::lcmt_policy_params&) { ++policies; });
  t.subscribe<masa::lcmt_actor_heartbeat>(kHeartbeatChannel, [&](const masa::lcmt_actor_heartbeat&) { ++heartbeats; });
  std::vector<uint8_t> crafted = encode(policy());
  put32(crafted, kNumParams, 0x7f7fffff);
  crafted.resize(77);
  t.publishRaw(kPolicyChannel, crafted.data(), static_cast<int>(crafted.size()));
  const std::vector<uint8_t> good = encode(policy());
  t.publishRaw(kPolicyChannel, good.data(), static_cast<int>(good.size()) - 1);
  t.publishRaw(kHeartbeatChannel, good.data(), static_cast<int>(good.size()));  // a policy on the heartbeat channel
  t.publish(kPolicyChannel, policy());
  t.drain();
  EXPECT_EQ(policies, 1);
  EXPECT_EQ(heartbeats, 0);
  const WireRejects on_policy = t.rejected(kPolicyChannel), on_heartbeat = t.rejected(kHeartbeatChannel);
  EXPECT_EQ(on_policy[static_cast<int>(WireVerdict::kOverLimit)], 1);
  EXPECT_EQ(on_policy[static_cast<int>(WireVerdict::kTruncated)], 1);
  EXPECT_EQ(on_heartbeat[static_cast<int>(WireVerdict::kWrongType)], 1);
  EXPECT_EQ(t.rejected(kLearnerStatsChannel), WireRejects{});
  EXPECT_EQ(t.decodeErrors(), 3);
  EXPECT_EQ(wireVerdictName(WireVerdict::kOverLimit), "over_limit");
}

}  // namespace
}  // namespace masa::transport
