// masa_lcm_fuzz: a hostile machine on the LAN, for testing. It listens to a live run's channels and
// republishes mutated copies of the newest message of each (transport::MessageMutator: bit flips,
// hostile length fields, truncation, extension, insertions) at a fixed rate, round-robin over the
// channels it has heard, until --duration or Ctrl-C; then prints what it sent per channel.
//   masa_lcm_fuzz --url 'udpm://239.255.76.67:7692?ttl=0' --rate 200 --duration 30 --seed 1
// It holds no run key: with authentication on, every copy must be dropped as unauthenticated; with
// --no-auth runs, the copies reach the wire guard and the validators behind it.
#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "common/core/build_info.hpp"
#include "common/transport/message_mutator.hpp"

namespace {

std::atomic<bool> g_stop{false};
extern "C" void onSignal(int) { g_stop.store(true); }

// The newest genuine message of each channel, and what was sent on it.
struct Channel {
  std::unique_ptr<masa::transport::MessageMutator> mutator;  // over the newest genuine message
  int64_t heard = 0;                                          // genuine messages received
  int64_t sent = 0;                                           // mutated copies published
};

std::size_t bytesHash(const void* data, std::size_t size) {
  return std::hash<std::string_view>{}(std::string_view(static_cast<const char*>(data), size));
}

// Keeps the newest genuine message per channel. The copies the fuzzer publishes come back to it
// over loopback: they are recognised by their hash, so that only genuine messages are mutated.
class Listener {
 public:
  explicit Listener(uint64_t seed) : next_seed_(seed) {}
  void onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& name) {
    if (own_.count(bytesHash(rbuf->data, rbuf->data_size))) return;
    Channel& c = channels[name];
    ++c.heard;
    const auto* bytes = static_cast<const uint8_t*>(rbuf->data);
    c.mutator = std::make_unique<masa::transport::MessageMutator>(
        std::vector<uint8_t>(bytes, bytes + rbuf->data_size), next_seed_++);
  }
  void sent(const std::vector<uint8_t>& copy) {
    if (own_.size() > 100000) own_.clear();  // bounded; a forgotten copy only becomes one mutation base
    own_.insert(bytesHash(copy.data(), copy.size()));
  }
  std::map<std::string, Channel> channels;

 private:
  std::unordered_set<std::size_t> own_;
  uint64_t next_seed_;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"masa lcm fuzz: republish mutated copies of a live run's messages (a test's hostile publisher)"};
  app.set_version_flag("--version", masa::buildCommit());
  std::string url, channel_regex = "MASA_.*";
  double rate = 200, duration = 0;
  uint64_t seed = 1;
  app.add_option("--url", url, "LCM provider URL (default: LCM's)");
  app.add_option("--channels", channel_regex, "channels to fuzz (an LCM channel regex)")->capture_default_str();
  app.add_option("--rate", rate, "mutated copies per second, over all channels")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--duration", duration, "seconds to run (0: until Ctrl-C or SIGTERM)")->check(CLI::NonNegativeNumber);
  app.add_option("--seed", seed, "seed of the mutations")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  try {
    lcm::LCM lcm(url);
    if (!lcm.good()) throw std::runtime_error("cannot open LCM at '" + url + "'");
    Listener listener(seed);
    lcm.subscribe(channel_regex, &Listener::onMessage, &listener);
    auto& channels = listener.channels;
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);

    const auto start = std::chrono::steady_clock::now();
    const auto period = std::chrono::duration<double>(1.0 / rate);
    auto next_send = start;
    std::size_t turn = 0;
    while (!g_stop.load()) {
      const auto now = std::chrono::steady_clock::now();
      if (duration > 0 && std::chrono::duration<double>(now - start).count() >= duration) break;
      const int wait_ms = std::max(0, static_cast<int>(std::chrono::duration<double, std::milli>(next_send - now).count()));
      lcm.handleTimeout(wait_ms);
      if (std::chrono::steady_clock::now() < next_send) continue;
      next_send += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
      std::vector<std::string> ready;
      for (const auto& [name, c] : channels)
        if (c.mutator) ready.push_back(name);
      if (ready.empty()) continue;
      const std::string& name = ready[turn++ % ready.size()];
      Channel& c = channels[name];
      const std::vector<uint8_t> copy = c.mutator->next();
      listener.sent(copy);
      lcm.publish(name, copy.data(), static_cast<unsigned int>(copy.size()));
      ++c.sent;
    }
    int64_t total = 0;
    for (const auto& [name, c] : channels) {
      std::printf("masa_lcm_fuzz: %s: %lld genuine messages heard, %lld mutated copies sent\n", name.c_str(),
                  static_cast<long long>(c.heard), static_cast<long long>(c.sent));
      total += c.sent;
    }
    std::printf("masa_lcm_fuzz: %lld mutated copies sent in all\n", static_cast<long long>(total));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_lcm_fuzz: %s\n", e.what());
    return 2;
  }
}
