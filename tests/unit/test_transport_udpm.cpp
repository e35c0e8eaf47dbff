// Over real multicast on this host (udpm, ttl=0): the transport the actors and the learner use.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "common/transport/lcm_url.hpp"
#include "learner/intake/rollout_assembler.hpp"
#include "actors/rollout_chunker.hpp"
#include "common/transport/transport.hpp"
#include "test_transport_support.hpp"

namespace masa::transport {
namespace {

// The actors' chunking and the learner's intake, tested against each other and the wire.
using namespace masa::actor;
using namespace masa::learner;

using Clock = std::chrono::steady_clock;

// Channel names unique to this process: other test processes may share the multicast group.
std::string uniqueChannel(const char* base) { return std::string(base) + "_" + std::to_string(::getpid()); }

// Empty when loopback multicast works (one small message published and received within 2 s),
// otherwise the reason it does not.
std::string multicastUnavailable(const std::string& url) {
  std::unique_ptr<Transport> t;
  try {
    t = std::make_unique<Transport>(url);
  } catch (const std::exception& e) {
    return e.what();
  }
  const std::string channel = uniqueChannel("MASA_TEST_PROBE");
  bool got = false;
  t->subscribeRaw(channel, [&](const void*, int) { got = true; });
  const char probe[16] = "probe";
  if (!t->publishRaw(channel, probe, sizeof probe)) return "publishing on " + url + " failed";
  const auto deadline = Clock::now() + std::chrono::seconds(2);
  while (!got && Clock::now() < deadline) t->handleTimeout(100);
  return got ? "" : "a message published on " + url + " did not come back within 2 s";
}

TEST(TransportUdpm, FiftyPacedChunksOfSixtyKilobytesMostlyArriveOnLoopback) {
  // The recv_buf_size LCM asks for is capped by net.core.rmem_max; ask for what the kernel grants
  // (4 MiB by default on Debian 12) so this test measures the configuration that works here.
  const RecvBufCheck rmem = checkRecvBuf(kDefaultRecvBufBytes);
  const int64_t recv_buf = rmem.rmem_max > 0 ? std::min<int64_t>(rmem.rmem_max, kDefaultRecvBufBytes)
                                             : kDefaultRecvBufBytes;
  const std::string url = loopbackUrl(recv_buf);
  const std::string why = multicastUnavailable(url);
  if (!why.empty()) GTEST_SKIP() << "loopback multicast unavailable: " << why;

  // 700 TriFinger environments (obs 41, act 9, T 16) = 50 chunks of 14 environments, ~57.5 KB.
  constexpr int kChunks = 50;
  rollout::Rollout rollout;
  testing::fillRandomRollout(rollout, {14 * kChunks, 16, 41, 9}, 7, 0.0);
  RolloutChunker chunker;
  const auto chunks = chunker.split(rollout, RolloutIdentity{.run_id = 21, .actor_id = 0, .rollout_seq = 0});
  ASSERT_EQ(static_cast<int>(chunks.size()), kChunks);
  ASSERT_GT(chunks[0].getEncodedSize(), 55000);
  ASSERT_LE(chunks[0].getEncodedSize(), kDefaultChunkBytes);

  AssemblerConfig cfg;
  cfg.run_id = 21;
  cfg.horizon = 16;
  cfg.obs_dim = 41;
  cfg.act_dim = 9;
  RolloutAssembler assembler(cfg);
  Transport subscriber(url);
  const std::string channel = uniqueChannel("MASA_TEST_ROLLOUT");
  int received = 0, accepted = 0;
  subscriber.subscribeRaw(channel, [&](const void* data, int size) {
    ++received;
    if (assembler.acceptEncoded(data, size)) ++accepted;
  });

  std::atomic<bool> published{false};
  std::thread publisher([&] {
    Transport pub(url);
    for (const auto& c : chunks) {
      pub.publish(channel, c);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    published = true;
  });
  // Bounded: stop 10 s after starting, or 500 ms after the last publication.
  const auto start = Clock::now();
  auto quiet_since = Clock::now();
  while (received < kChunks && Clock::now() - start < std::chrono::seconds(10)) {
    if (subscriber.handleTimeout(50) > 0) quiet_since = Clock::now();
    if (published && Clock::now() - quiet_since > std::chrono::milliseconds(500)) break;
  }
  publisher.join();
  EXPECT_LT(Clock::now() - start, std::chrono::seconds(11));
  EXPECT_GE(accepted, kChunks * 9 / 10) << received << " of " << kChunks << " received";
  EXPECT_EQ(accepted, received);  // what arrives is intact
  RecordProperty("chunks_received", received);
}

}  // namespace
}  // namespace masa::transport
