// common/transport/log_bus.hpp and lcm_log_reader.hpp: a log written by LCM's own writer (the
// format lcm-logger writes) replays through the MessageBus interface as the network would deliver
// it: typed subscribers get the decoded message, raw ones the bytes, patterns match as LCM's do,
// a damaged message is refused and counted, and the receive times are the log's. A damaged log
// file (every truncation, random byte changes, a huge length) ends the replay without a crash or
// an allocation past the file's size.
#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "common/transport/channels.hpp"
#include "common/transport/log_bus.hpp"
#include "masa/lcmt_policy_params.hpp"

namespace masa::transport {
namespace {

namespace fs = std::filesystem;

std::vector<uint8_t> encoded(const masa::lcmt_policy_params& m) {
  std::vector<uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

masa::lcmt_policy_params params(int64_t version) {
  masa::lcmt_policy_params m{};
  m.run_id = 42;
  m.version = version;
  m.utime = 1000 + version;
  m.task = "a1_beam";
  m.num_params = 3;
  m.params = {0.5f, -1.0f, 2.0f * static_cast<float>(version)};
  return m;
}

struct Recorded {
  std::string channel;
  int64_t time_us;
  std::vector<uint8_t> data;
};

void writeLog(const std::string& path, const std::vector<Recorded>& events) {
  lcm::LogFile log(path, "w");
  ASSERT_TRUE(log.good());
  int64_t n = 0;
  for (const Recorded& r : events) {
    lcm::LogEvent e{n++, r.time_us, r.channel, static_cast<int32_t>(r.data.size()), const_cast<uint8_t*>(r.data.data())};
    ASSERT_EQ(log.writeEvent(&e), 0);
  }
}

std::string tempPath(const std::string& name) { return (fs::temp_directory_path() / ("masa_log_bus_" + name)).string(); }

std::vector<Recorded> aRun() {
  std::vector<Recorded> events;
  for (int v = 1; v <= 5; ++v) {
    events.push_back({kPolicyChannel, 2'000'000 + 10'000 * v, encoded(params(v))});
    events.push_back({kRolloutChannel, 2'000'000 + 10'000 * v + 5, std::vector<uint8_t>(100 + v, static_cast<uint8_t>(v))});
  }
  events.push_back({"OTHER", 3'000'000, {1, 2, 3}});
  return events;
}

TEST(LogBus, ALogReplaysAsTheNetworkDeliversItTypedRawAndByPattern) {
  const std::string path = tempPath("replay.lcmlog");
  const std::vector<Recorded> events = aRun();
  writeLog(path, events);
  LogBus bus(path);
  std::vector<int64_t> versions, typed_times;
  std::vector<std::string> raw_channels;
  std::vector<std::size_t> raw_sizes;
  bus.subscribe<masa::lcmt_policy_params>(kPolicyChannel, [&](const masa::lcmt_policy_params& m) {
    versions.push_back(m.version);
    typed_times.push_back(bus.eventTimeUs());
    EXPECT_EQ(m.params[2], 2.0f * static_cast<float>(m.version));
  });
  bus.subscribeRaw("MASA_.*", [&](const void*, int size) {
    raw_sizes.push_back(static_cast<std::size_t>(size));
  });
  int dispatched = 0, r;
  while ((r = bus.handleTimeout(100)) > 0) ++dispatched;
  EXPECT_EQ(r, 0);
  EXPECT_TRUE(bus.ended());
  EXPECT_EQ(dispatched, static_cast<int>(events.size()));
  EXPECT_EQ(versions, (std::vector<int64_t>{1, 2, 3, 4, 5}));
  EXPECT_EQ(typed_times, (std::vector<int64_t>{2'010'000, 2'020'000, 2'030'000, 2'040'000, 2'050'000}));
  ASSERT_EQ(raw_sizes.size(), 10u) << "OTHER matched MASA_.* or a MASA_ event was missed";
  EXPECT_EQ(raw_sizes[1], 101u);
  EXPECT_EQ(bus.decodeErrors(), 0);
  EXPECT_FALSE(bus.publish(kPolicyChannel, params(9))) << "a log is read-only";
  EXPECT_FALSE(bus.publishRaw("X", "x", 1));
  fs::remove(path);
}

TEST(LogBus, ADamagedMessageInTheLogIsRefusedAndCountedNotDelivered) {
  const std::string path = tempPath("damaged_message.lcmlog");
  std::vector<uint8_t> cut = encoded(params(1));
  cut.resize(cut.size() - 5);
  writeLog(path, {{kPolicyChannel, 1, cut}, {kPolicyChannel, 2, encoded(params(2))}});
  LogBus bus(path);
  std::vector<int64_t> versions;
  bus.subscribe<masa::lcmt_policy_params>(kPolicyChannel, [&](const masa::lcmt_policy_params& m) { versions.push_back(m.version); });
  EXPECT_EQ(bus.drain(), 2);
  EXPECT_EQ(versions, (std::vector<int64_t>{2}));
  EXPECT_EQ(bus.decodeErrors(), 1);
  fs::remove(path);
}

// Replays a log file's bytes; returns the events dispatched, or -1 when the bus said "damaged".
int replay(const std::string& path, const std::vector<uint8_t>& bytes, std::string* error = nullptr) {
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  LogBus bus(path);
  bus.subscribeRaw(".*", [](const void*, int) {});
  bus.subscribe<masa::lcmt_policy_params>(kPolicyChannel, [](const masa::lcmt_policy_params&) {});
  int n = 0, r;
  while ((r = bus.handleTimeout(0)) > 0) ++n;
  if (error) *error = bus.error();
  return r < 0 ? -1 : n;
}

TEST(LogBus, EveryTruncationEndsTheReplayAtTheLastWholeEvent) {
  const std::string path = tempPath("whole.lcmlog"), cut_path = tempPath("cut.lcmlog");
  writeLog(path, aRun());
  std::ifstream in(path, std::ios::binary);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(replay(cut_path, bytes), 11);
  int last = 0;
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    const int events = replay(cut_path, std::vector<uint8_t>(bytes.begin(), bytes.begin() + static_cast<long>(n)));
    ASSERT_GE(events, last) << "cut at " << n;  // more bytes never give fewer whole events
    ASSERT_LT(events, 11) << "cut at " << n;
    last = events;
  }
  fs::remove(path);
  fs::remove(cut_path);
}

TEST(LogBus, ADamagedLogEndsWithANamedErrorOrAtItsEndAndNeverAllocatesPastTheFile) {
  const std::string path = tempPath("fuzz_src.lcmlog"), fuzz_path = tempPath("fuzz.lcmlog");
  writeLog(path, aRun());
  std::ifstream in(path, std::ios::binary);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The first event's data length (bytes 24-27 of its header) set to 2 GB: the end, no allocation.
  std::vector<uint8_t> huge = bytes;
  huge[24] = 0x7f, huge[25] = 0xff, huge[26] = 0xff, huge[27] = 0xff;
  EXPECT_EQ(replay(fuzz_path, huge), 0);
  // A broken sync word: named.
  std::vector<uint8_t> unsynced = bytes;
  unsynced[0] ^= 0x10;
  std::string error;
  EXPECT_EQ(replay(fuzz_path, unsynced, &error), -1);
  EXPECT_NE(error.find("no sync word at byte 0"), std::string::npos) << error;
  EXPECT_NE(error.find(fuzz_path), std::string::npos) << error;
  std::mt19937_64 rng(7);
  int damaged = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::vector<uint8_t> b = bytes;
    const int changes = 1 + static_cast<int>(rng() % 4);
    for (int c = 0; c < changes; ++c) b[rng() % b.size()] = static_cast<uint8_t>(rng());
    const int r = replay(fuzz_path, b);
    ASSERT_LE(r, 11) << "trial " << trial;
    damaged += r < 0;
  }
  EXPECT_GT(damaged, 0) << "no change was ever noticed as damage";
  fs::remove(path);
  fs::remove(fuzz_path);
}

TEST(LogBus, AMissingLogIsNamed) {
  try {
    LogBus bus("/nonexistent/run.lcmlog");
    FAIL() << "a missing log was opened";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/run.lcmlog"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace masa::transport
