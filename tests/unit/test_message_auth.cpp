// Message authentication: the trailer alone (MessageAuthenticator), and through the path every
// process receives by (Transport with a run key over memq://): what is signed with the run key is
// handled with exactly its original bytes; what is signed with another key, unsigned, or signed for
// another channel is dropped, counted under "unauthenticated", and never reaches a handler.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "common/transport/channels.hpp"
#include "common/transport/message_auth.hpp"
#include "common/transport/transport.hpp"
#include "masa/lcmt_policy_params.hpp"
#include "test_transport_support.hpp"

namespace masa::transport {
namespace {

using testing::encode;
using testing::samplePolicy;

// `message` followed by the trailer `key` gives it on `channel`.
std::vector<uint8_t> sealed(const RunKey& key, const std::string& channel, const std::vector<uint8_t>& message) {
  std::vector<uint8_t> out(message);
  out.resize(message.size() + kAuthTrailerBytes);
  MessageAuthenticator(key).seal(channel, message.data(), static_cast<int>(message.size()), out.data() + message.size());
  return out;
}

int openWith(const RunKey& key, const std::string& channel, const std::vector<uint8_t>& bytes) {
  return MessageAuthenticator(key).open(channel, bytes.data(), static_cast<int>(bytes.size()));
}

TEST(MessageAuth, ASealedMessageOpensOnlyWithItsKeyOnItsChannelAndUnchanged) {
  const RunKey key = RunKey::random(), other = RunKey::random();
  const std::vector<uint8_t> message = encode(samplePolicy());
  const std::vector<uint8_t> bytes = sealed(key, kPolicyChannel, message);
  ASSERT_EQ(bytes.size(), message.size() + 36);
  EXPECT_EQ(std::memcmp(bytes.data() + message.size(), "MAC1", 4), 0);
  EXPECT_EQ(openWith(key, kPolicyChannel, bytes), static_cast<int>(message.size()));
  EXPECT_EQ(openWith(other, kPolicyChannel, bytes), -1) << "another key";
  EXPECT_EQ(openWith(key, kHeartbeatChannel, bytes), -1) << "another channel";
  EXPECT_EQ(openWith(key, kPolicyChannel, message), -1) << "unsigned";
  EXPECT_EQ(openWith(key, kPolicyChannel, std::vector<uint8_t>(bytes.begin() + 1, bytes.end())), -1) << "cut";
  EXPECT_EQ(openWith(key, kPolicyChannel, std::vector<uint8_t>(bytes.begin(), bytes.begin() + 20)), -1) << "short";
  EXPECT_EQ(MessageAuthenticator(key).open(kPolicyChannel, nullptr, 0), -1);
  // One flipped bit anywhere, in the message or in the tag.
  for (std::size_t at : {std::size_t{0}, message.size() / 2, message.size() - 1, message.size() + 4, bytes.size() - 1}) {
    std::vector<uint8_t> flipped = bytes;
    flipped[at] ^= 0x01;
    EXPECT_EQ(openWith(key, kPolicyChannel, flipped), -1) << "bit flipped at byte " << at;
  }
  // The channel and the message cannot trade bytes: "AB" + "C..." is not "A" + "BC...".
  const std::vector<uint8_t> abc = {'C', 'D'};
  std::vector<uint8_t> bcd = {'B', 'C', 'D'};
  bcd.resize(bcd.size() + kAuthTrailerBytes);
  std::memcpy(bcd.data() + 3, sealed(key, "AB", abc).data() + 2, kAuthTrailerBytes);
  EXPECT_EQ(openWith(key, "A", bcd), -1);
}

TEST(MessageAuth, WithoutTheKeyOnlyTheTrailerIsSkippedUnchecked) {
  const std::vector<uint8_t> message = encode(samplePolicy());
  const std::vector<uint8_t> bytes = sealed(RunKey::random(), kPolicyChannel, message);
  EXPECT_EQ(sizeBeforeTrailer(bytes.data(), static_cast<int>(bytes.size())), static_cast<int>(message.size()));
  EXPECT_EQ(sizeBeforeTrailer(message.data(), static_cast<int>(message.size())), static_cast<int>(message.size()));
}

// A keyed in-process transport with a raw and a typed subscriber on MASA_POLICY.
struct KeyedBus {
  RunKey key = RunKey::random();
  Transport bus{"memq://", key};
  std::vector<std::vector<uint8_t>> raw;
  std::vector<masa::lcmt_policy_params> typed;

  KeyedBus() {
    bus.subscribeRaw(kPolicyChannel, [this](const void* data, int size) {
      const auto* p = static_cast<const uint8_t*>(data);
      raw.emplace_back(p, p + size);
    });
    bus.subscribe<masa::lcmt_policy_params>(kPolicyChannel, [this](const masa::lcmt_policy_params& m) { typed.push_back(m); });
  }
  void drain() {
    for (int i = 0; i < 5; ++i) bus.handleTimeout(10);
  }
  int64_t unauthenticated() const { return bus.rejected(kPolicyChannel)[static_cast<int>(WireVerdict::kUnauthenticated)]; }
};

TEST(MessageAuthTransport, WithTheRunKeyAMessageIsHandledWithExactlyItsOriginalBytes) {
  KeyedBus b;
  ASSERT_TRUE(b.bus.authenticates());
  const std::vector<uint8_t> message = encode(samplePolicy());
  ASSERT_TRUE(b.bus.publish(kPolicyChannel, samplePolicy()));
  ASSERT_TRUE(b.bus.publishRaw(kPolicyChannel, message.data(), static_cast<int>(message.size())));
  ASSERT_TRUE(b.bus.publishWire(kPolicyChannel, sealed(b.key, kPolicyChannel, message).data(),
                                static_cast<int>(message.size()) + kAuthTrailerBytes));
  b.drain();
  ASSERT_EQ(b.raw.size(), 3u);
  for (const auto& got : b.raw) EXPECT_EQ(got, message) << "the trailer is stripped, nothing else changes";
  ASSERT_EQ(b.typed.size(), 3u);
  EXPECT_EQ(encode(b.typed[0]), message);
  EXPECT_EQ(b.bus.decodeErrors(), 0);
}

TEST(MessageAuthTransport, SignedWithAnotherKeyIsDroppedCountedAndNeverHandled) {
  KeyedBus b;
  const std::vector<uint8_t> forged = sealed(RunKey::random(), kPolicyChannel, encode(samplePolicy()));
  ASSERT_TRUE(b.bus.publishWire(kPolicyChannel, forged.data(), static_cast<int>(forged.size())));
  b.drain();
  EXPECT_TRUE(b.raw.empty());
  EXPECT_TRUE(b.typed.empty());
  EXPECT_EQ(b.unauthenticated(), 2) << "once per subscription, like every rejection";
  EXPECT_EQ(b.bus.decodeErrors(), 2);
  EXPECT_EQ(wireVerdictName(WireVerdict::kUnauthenticated), "unauthenticated");
}

TEST(MessageAuthTransport, AnUnsignedMessageOnAKeyedTransportIsDroppedAndCounted) {
  KeyedBus b;
  const std::vector<uint8_t> message = encode(samplePolicy());
  ASSERT_TRUE(b.bus.publishWire(kPolicyChannel, message.data(), static_cast<int>(message.size())));
  const uint8_t junk[3] = {1, 2, 3};
  ASSERT_TRUE(b.bus.publishWire(kPolicyChannel, junk, sizeof junk));
  b.drain();
  EXPECT_TRUE(b.raw.empty());
  EXPECT_TRUE(b.typed.empty());
  EXPECT_EQ(b.unauthenticated(), 4);
}

TEST(MessageAuthTransport, AMessageAndItsTagMovedToAnotherChannelAreDropped) {
  KeyedBus b;
  // Signed with the run key, but for the stats channel: replayed on the policy channel.
  const std::vector<uint8_t> moved = sealed(b.key, kLearnerStatsChannel, encode(samplePolicy()));
  ASSERT_TRUE(b.bus.publishWire(kPolicyChannel, moved.data(), static_cast<int>(moved.size())));
  b.drain();
  EXPECT_TRUE(b.raw.empty());
  EXPECT_TRUE(b.typed.empty());
  EXPECT_EQ(b.unauthenticated(), 2);
}

TEST(MessageAuthTransport, WithoutAKeyBytesPassUnchangedBothWays) {
  Transport bus("memq://");
  EXPECT_FALSE(bus.authenticates());
  std::vector<uint8_t> got;
  bus.subscribeRaw(kPolicyChannel, [&](const void* data, int size) {
    got.assign(static_cast<const uint8_t*>(data), static_cast<const uint8_t*>(data) + size);
  });
  const std::vector<uint8_t> message = encode(samplePolicy());
  ASSERT_TRUE(bus.publishRaw(kPolicyChannel, message.data(), static_cast<int>(message.size())));
  bus.handleTimeout(100);
  EXPECT_EQ(got, message);
}

}  // namespace
}  // namespace masa::transport
