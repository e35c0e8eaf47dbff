// The two MessageBus implementations deliver the same messages to the same subscribers: Transport
// (LCM, here on memq://) and LocalBus (one process, typed messages never encoded).
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "common/transport/channels.hpp"
#include "common/transport/local_bus.hpp"
#include "common/transport/transport.hpp"
#include "masa/lcmt_actor_heartbeat.hpp"
#include "test_transport_support.hpp"

namespace masa::transport {
namespace {

using testing::encode;
using testing::samplePolicy;

lcmt_actor_heartbeat busHeartbeat() {
  lcmt_actor_heartbeat h{};
  h.run_id = 42;
  h.actor_id = 3;
  h.hostname = "node-a";
  h.num_envs = 8;
  h.policy_version = -1;
  h.params_version = -1;
  return h;
}

std::string bytesSeen(const void* data, int size) {
  const std::string_view bytes(static_cast<const char*>(data), static_cast<std::size_t>(size));
  return "raw " + std::to_string(size) + " bytes, hash " + std::to_string(std::hash<std::string_view>{}(bytes));
}

// One script of publishes and subscriptions: what the subscribers saw, in order, and the rejects.
std::vector<std::string> runScript(MessageBus& bus) {
  std::vector<std::string> seen;
  bus.subscribe<lcmt_policy_params>(kPolicyChannel, [&](const lcmt_policy_params& p) {
    seen.push_back("policy v" + std::to_string(p.version) + " of " + std::to_string(p.params.size()) + ", first " +
                   std::to_string(p.params.front()));
  });
  const MessageBus::SubscriptionId raw =
      bus.subscribeRaw(kPolicyChannel, [&](const void* data, int size) { seen.push_back(bytesSeen(data, size)); });
  bus.subscribe<lcmt_actor_heartbeat>("MASA_ACTOR_.*", [&](const lcmt_actor_heartbeat& h) {
    seen.push_back("heartbeat of actor " + std::to_string(h.actor_id) + " on " + h.hostname);
  });

  lcmt_policy_params policy = samplePolicy();
  EXPECT_TRUE(bus.publish(kPolicyChannel, policy));
  // Changed after publishing: what arrives is what was published.
  policy.version = 18;
  policy.params[0] = 7.0f;
  const std::vector<uint8_t> heartbeat = encode(busHeartbeat()), later_policy = encode(policy);
  EXPECT_TRUE(bus.publishRaw(kHeartbeatChannel, heartbeat.data(), static_cast<int>(heartbeat.size())));
  // Three bytes short: the raw subscriber gets it, the typed one's guard refuses it.
  EXPECT_TRUE(bus.publishRaw(kPolicyChannel, later_policy.data(), static_cast<int>(later_policy.size()) - 3));
  // A heartbeat on the policy channel: of the wrong type for the typed subscriber.
  EXPECT_TRUE(bus.publish(kPolicyChannel, busHeartbeat()));
  seen.push_back("drained " + std::to_string(bus.drain()));

  bus.unsubscribe(raw);
  EXPECT_TRUE(bus.publish(kPolicyChannel, policy));
  EXPECT_EQ(bus.handleTimeout(1000), 1);
  EXPECT_EQ(bus.handleTimeout(0), 0);
  seen.push_back("rejected: " + bus.rejectSummary());
  return seen;
}

TEST(MessageBus, LcmAndTheInProcessBusDeliverTheSameMessagesToTheSameSubscribers) {
  Transport lcm("memq://");
  LocalBus local;
  const std::vector<std::string> by_lcm = runScript(lcm), by_local = runScript(local);
  EXPECT_EQ(by_local, by_lcm);

  // And what they deliver is the script's, not merely alike.
  const std::vector<uint8_t> first = encode(samplePolicy()), heartbeat = encode(busHeartbeat());
  ASSERT_EQ(by_local.size(), 8u);
  EXPECT_EQ(by_local[0], "policy v17 of 40, first -0.200000");
  EXPECT_EQ(by_local[1], bytesSeen(first.data(), static_cast<int>(first.size())));
  EXPECT_EQ(by_local[2], "heartbeat of actor 3 on node-a");
  EXPECT_EQ(by_local[3].substr(0, 4), "raw ");  // the short policy, for the raw subscriber alone
  EXPECT_EQ(by_local[4], bytesSeen(heartbeat.data(), static_cast<int>(heartbeat.size())));
  EXPECT_EQ(by_local[5], "drained 4");
  EXPECT_EQ(by_local[6], "policy v18 of 40, first 7.000000");
  EXPECT_EQ(by_local[7], "rejected: MASA_POLICY: wrong_type 1, truncated 1");
  EXPECT_EQ(local.rejected(kPolicyChannel)[static_cast<int>(WireVerdict::kTruncated)], 1);
  EXPECT_EQ(local.decodeErrors(), 2);
}

// The in-process bus hands a typed subscriber of the type the object itself, never encoded: a
// heartbeat whose host name holds a NUL, which LCM's C-string encoding cannot carry (Transport
// refuses to publish it), arrives whole; a raw subscriber, which needs the bytes, gets nothing.
TEST(MessageBus, TheInProcessBusHandsTypedMessagesOverWithoutEncodingThem) {
  lcmt_actor_heartbeat h = busHeartbeat();
  h.hostname = std::string("node\0a", 6);
  Transport lcm("memq://");
  EXPECT_FALSE(lcm.publish(kHeartbeatChannel, h));

  LocalBus bus;
  std::string typed_host;
  int raw_calls = 0;
  bus.subscribe<lcmt_actor_heartbeat>(kHeartbeatChannel, [&](const lcmt_actor_heartbeat& m) { typed_host = m.hostname; });
  bus.subscribeRaw(kHeartbeatChannel, [&](const void*, int) { ++raw_calls; });
  ASSERT_TRUE(bus.publish(kHeartbeatChannel, h));
  ASSERT_EQ(bus.drain(), 1);
  EXPECT_EQ(typed_host, h.hostname);
  EXPECT_EQ(typed_host.size(), 6u);
  EXPECT_EQ(raw_calls, 0);
}

TEST(MessageBus, TheInProcessBusWaitsForAMessageFromAnotherThread) {
  LocalBus bus;
  int handled = 0;
  bus.subscribe<lcmt_policy_params>(kPolicyChannel, [&](const lcmt_policy_params&) { ++handled; });
  EXPECT_EQ(bus.handleTimeout(10), 0);
  std::thread publisher([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    bus.publish(kPolicyChannel, samplePolicy());
  });
  EXPECT_EQ(bus.handleTimeout(5000), 1);
  publisher.join();
  EXPECT_EQ(handled, 1);
}

TEST(MessageBus, AHandlerMayUnsubscribeItselfAndTheOthersStillGetTheMessage) {
  LocalBus bus;
  int first = 0, second = 0;
  MessageBus::SubscriptionId self = -1;
  self = bus.subscribe<lcmt_policy_params>(kPolicyChannel, [&](const lcmt_policy_params&) {
    ++first;
    bus.unsubscribe(self);
  });
  bus.subscribe<lcmt_policy_params>(kPolicyChannel, [&](const lcmt_policy_params&) { ++second; });
  bus.publish(kPolicyChannel, samplePolicy());
  bus.publish(kPolicyChannel, samplePolicy());
  EXPECT_EQ(bus.drain(), 2);
  EXPECT_EQ(first, 1);
  EXPECT_EQ(second, 2);
}

}  // namespace
}  // namespace masa::transport
