// masa_lcm_probe: listen on masa's LCM channels and report, per channel, how many messages came,
// their size, their rate and (for messages that carry a publication time, utime) the latency from
// publication to reception. Publisher and probe must share a clock: on one host this is exact;
// across hosts it is only as good as their clock synchronization.
//   masa_lcm_probe                                       # MASA_POLICY on the loopback URL, until Ctrl-C
//   masa_lcm_probe --channel MASA_POLICY --duration 60 --run-id 42 --csv policy.csv
//   masa_lcm_probe --all --url 'udpm://239.255.76.67:7690?ttl=0&recv_buf_size=8388608'
// The latency includes what the publisher does after stamping utime (encoding, sending every
// fragment), the network, LCM's reassembly and the probe's own scheduling: under load, it is what
// a subscriber that polls without delay would see.
// With --key-file (a run's run.key) only messages with a valid tag count, with --roster (a signed
// run's roster) only messages whose signature, sender, channel and counter verify; the others are
// reported by reason. Without either, a message's trailer is skipped unchecked (the probe only watches).
// With --log FILE it reads a recording instead (lcm-logger's log, through LogBus): the same table,
// each message's time being when the logger received it, so the latency is publication to logger.
//   lcm-logger run.lcmlog & ... ; masa_lcm_probe --log run.lcmlog --all --quiet
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/core/build_info.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/lcm_url.hpp"
#include "common/transport/log_bus.hpp"
#include "common/transport/message_auth.hpp"
#include "common/transport/roster.hpp"
#include "common/transport/run_key.hpp"
#include "common/transport/transport.hpp"
#include "common/transport/wire_guard.hpp"
#include "masa/lcmt_actor_heartbeat.hpp"
#include "masa/lcmt_learner_stats.hpp"
#include "masa/lcmt_policy_params.hpp"

namespace {

using namespace masa;

std::atomic<bool> g_stop{false};
extern "C" void onSignal(int) { g_stop.store(true); }

// What the probe can read from one message: run id, publication time, and a version or sequence
// where the type has one. Channels of unknown type give none of these.
struct Stamp {
  int64_t run_id = 0;
  int64_t utime = 0;
  int64_t version = -1;
};

// Through the wire guard, as every masa process decodes: the probe listens to hostile LANs too.
template <class Msg>
std::optional<Msg> decodeAs(const void* data, int size) {
  Msg m;
  if (transport::decodeChecked(data, size, m) == transport::WireVerdict::kOk) return m;
  return std::nullopt;
}

std::optional<Stamp> readStamp(const std::string& channel, const void* data, int size) {
  if (channel == transport::kPolicyChannel) {
    if (auto m = decodeAs<masa::lcmt_policy_params>(data, size)) return Stamp{m->run_id, m->utime, m->version};
  } else if (channel == transport::kLearnerStatsChannel) {
    if (auto m = decodeAs<masa::lcmt_learner_stats>(data, size)) return Stamp{m->run_id, m->utime, m->update};
  } else if (channel == transport::kHeartbeatChannel) {
    if (auto m = decodeAs<masa::lcmt_actor_heartbeat>(data, size)) return Stamp{m->run_id, m->utime, m->actor_id};
  }
  return std::nullopt;
}

// Nearest-rank percentile of a sorted sample.
double percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return 0.0;
  const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(sorted.size())));
  return sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1];
}

struct ChannelLog {
  int64_t messages = 0, bytes = 0, undecoded = 0, unauthenticated = 0;
  std::vector<double> sizes, latencies_ms;
  std::map<int64_t, int> versions;  // policy version -> times received (repeats are normal)
  int64_t first_us = 0, last_us = 0;
};

struct ProbeArgs {
  std::string url = transport::loopbackUrl();
  std::vector<std::string> channels;
  bool quiet = false;
  double duration_s = 0.0;
  int64_t max_count = 0, run_id = 0;
  std::string csv_path, key_file, roster_file, log_path;
};

// Parses the command line; returns an exit code when the program should end now, or -1 to go on.
int parseArgs(int argc, char** argv, ProbeArgs& a) {
  CLI::App app{"Report message counts, sizes, rates and publication-to-reception latency on masa's LCM channels"};
  app.set_version_flag("--version", masa::buildCommit());
  bool all = false;
  app.add_option("--url", a.url, "LCM provider URL")->capture_default_str();
  app.add_option("--channel", a.channels, "channel to listen on (repeatable; default MASA_POLICY)");
  app.add_flag("--all", all, "listen on all four masa channels");
  app.add_option("--duration", a.duration_s, "stop after this many seconds (0: until Ctrl-C or --count)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--count", a.max_count, "stop after this many messages in all (0: no limit)")->check(CLI::NonNegativeNumber);
  app.add_option("--run-id", a.run_id, "count only messages of this run (0: any run)");
  app.add_option("--csv", a.csv_path, "write one row per message: channel,recv_us,utime,latency_us,bytes,version");
  app.add_flag("--quiet", a.quiet, "print the summary only, not one line per message");
  auto* key_opt =
      app.add_option("--key-file", a.key_file, "the run's run.key: count only messages with a valid tag (default: tags unchecked)");
  app.add_option("--roster", a.roster_file,
                 "a signed run's RUN_DIR/roster: count only messages whose signature, sender, channel and counter "
                 "verify (no key needed)")
      ->excludes(key_opt);
  app.add_option("--log", a.log_path, "read this lcm-logger log instead of the network (its messages unverified)")
      ->check(CLI::ExistingFile);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (!a.log_path.empty() && (!a.key_file.empty() || !a.roster_file.empty() || a.duration_s > 0)) {
    std::fprintf(stderr, "masa_lcm_probe: --log replays a recording unverified and whole: no --key-file, --roster or --duration\n");
    return 2;
  }
  if (all)
    a.channels = {transport::kPolicyChannel, transport::kLearnerStatsChannel, transport::kHeartbeatChannel,
                  transport::kRolloutChannel};
  if (a.channels.empty()) a.channels = {transport::kPolicyChannel};
  return -1;
}

// What the probe heard, per channel, and the CSV row of each message.
class ProbeRecorder {
 public:
  ProbeRecorder(const ProbeArgs& a, std::ofstream& csv) : a_(a), csv_(csv) {
    for (const std::string& ch : a.channels) logs_[ch];
  }

  // One message received at `now` (wall clock, microseconds), its trailer already set aside.
  void record(const std::string& ch, const void* data, int size, int64_t now) {
    const auto stamp = readStamp(ch, data, size);
    if (stamp && a_.run_id != 0 && stamp->run_id != a_.run_id) return;
    ChannelLog& log = logs_[ch];
    if (log.messages == 0) log.first_us = now;
    log.last_us = now;
    ++log.messages;
    ++total_;
    log.bytes += size;
    log.sizes.push_back(size);
    double latency_us = -1.0;
    if (stamp) {
      latency_us = static_cast<double>(now - stamp->utime);
      log.latencies_ms.push_back(latency_us / 1000.0);
      if (ch == transport::kPolicyChannel) ++log.versions[stamp->version];
    } else if (ch != transport::kRolloutChannel) {
      ++log.undecoded;
    }
    if (csv_.is_open())
      csv_ << ch << ',' << now << ',' << (stamp ? stamp->utime : 0) << ',' << latency_us << ',' << size << ','
           << (stamp ? stamp->version : -1) << '\n';
    if (!a_.quiet && stamp)
      std::printf("%s  %d B  version/id %lld  latency %.3f ms\n", ch.c_str(), size, static_cast<long long>(stamp->version),
                  latency_us / 1000.0);
  }

  // The transport's refusals per channel: with a run key, messages without a valid tag; with a
  // roster, every reason a signed run refuses for (signature, sender, channel, claim, counter).
  void countRefusals(transport::Transport& bus) {
    for (auto& [ch, log] : logs_) {
      if (a_.roster_file.empty()) {
        log.unauthenticated = bus.rejected(ch)[static_cast<int>(transport::WireVerdict::kUnauthenticated)];
      } else {
        for (int64_t n : bus.rejected(ch)) log.unauthenticated += n;
      }
    }
  }

  int64_t total() const { return total_; }
  void printSummary();

 private:
  const ProbeArgs& a_;
  std::ofstream& csv_;
  std::map<std::string, ChannelLog> logs_;
  int64_t total_ = 0;
};

void ProbeRecorder::printSummary() {
  std::printf("channel               count   rate/s    MB/s  bytes(median)  bytes(max)  latency ms: median     p99     max\n");
  for (auto& [ch, log] : logs_) {
    std::sort(log.sizes.begin(), log.sizes.end());
    std::sort(log.latencies_ms.begin(), log.latencies_ms.end());
    const double span_s = (log.last_us - log.first_us) / 1e6;
    // Rate over the span between the first and the last message (n - 1 intervals).
    const double rate = span_s > 0 ? (log.messages - 1) / span_s : 0.0;
    const double mbps = span_s > 0 ? log.bytes / span_s / 1e6 : 0.0;
    std::printf("%-20s %6lld %8.1f %7.2f %14.0f %11.0f", ch.c_str(), static_cast<long long>(log.messages), rate, mbps,
                percentile(log.sizes, 50), log.sizes.empty() ? 0.0 : log.sizes.back());
    if (!log.latencies_ms.empty())
      std::printf("             %7.3f %7.3f %7.3f", percentile(log.latencies_ms, 50), percentile(log.latencies_ms, 99),
                  log.latencies_ms.back());
    std::printf("\n");
    if (!log.versions.empty()) {
      // Versions received, and those never seen between the first and the last (lost broadcasts
      // that were not repeated before the next one replaced them).
      const int64_t lo = log.versions.begin()->first, hi = log.versions.rbegin()->first;
      const int64_t missing = (hi - lo + 1) - static_cast<int64_t>(log.versions.size());
      std::printf("  %s: versions %lld..%lld, %zu distinct, %lld never received\n", ch.c_str(),
                  static_cast<long long>(lo), static_cast<long long>(hi), log.versions.size(),
                  static_cast<long long>(missing));
    }
    if (log.undecoded > 0)
      std::printf("  %s: %lld messages did not decode as the channel's type\n", ch.c_str(),
                  static_cast<long long>(log.undecoded));
    if (log.unauthenticated > 0)
      std::printf(a_.roster_file.empty() ? "  %s: %lld messages without a valid tag of the run key, not counted above\n"
                                         : "  %s: %lld messages refused by the roster's checks, not counted above\n",
                  ch.c_str(), static_cast<long long>(log.unauthenticated));
  }
}

// The bus the probe listens on: plain, checking a run key's tags, or verifying a roster's signatures.
std::unique_ptr<transport::Transport> openBus(const ProbeArgs& a, const std::optional<transport::RunKey>& key) {
  if (a.roster_file.empty()) return std::make_unique<transport::Transport>(a.url, key);
  return std::make_unique<transport::Transport>(
      a.url, transport::SignedMode{nullptr, std::make_shared<const transport::Roster>(transport::Roster::load(a.roster_file)), {}});
}

// Receives until a signal, --count or --duration; false on an LCM error.
bool listen(const ProbeArgs& a, transport::Transport& bus, const ProbeRecorder& recorder) {
  const auto start = std::chrono::steady_clock::now();
  while (!g_stop.load()) {
    if (bus.handleTimeout(100) < 0) {
      if (g_stop.load()) break;  // the signal interrupted the wait: a normal end
      std::fprintf(stderr, "masa_lcm_probe: LCM error while receiving\n");
      return false;
    }
    if (a.max_count > 0 && recorder.total() >= a.max_count) break;
    if (a.duration_s > 0 && std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= a.duration_s)
      break;
  }
  return true;
}

// Reads a recorded log to its end (or --count); false when the log is damaged (said why).
bool replayLog(const ProbeArgs& a, ProbeRecorder& recorder) {
  transport::LogBus bus(a.log_path);
  for (const std::string& ch : a.channels) {
    bus.subscribeRaw(ch, [&, ch](const void* data, int size) {
      recorder.record(ch, data, transport::sizeBeforeTrailer(data, size), bus.eventTimeUs());
    });
  }
  std::fprintf(stderr, "masa_lcm_probe: reading the log %s (tags and signatures not checked)\n", a.log_path.c_str());
  int r;
  while ((r = bus.handleTimeout(0)) > 0 && !g_stop.load())
    if (a.max_count > 0 && recorder.total() >= a.max_count) break;
  if (r < 0) {
    std::fprintf(stderr, "masa_lcm_probe: %s\n", bus.error().c_str());
    return false;
  }
  std::fprintf(stderr, "masa_lcm_probe: %lld events read from the log\n", static_cast<long long>(bus.events()));
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  ProbeArgs a;
  if (const int code = parseArgs(argc, argv, a); code >= 0) return code;

  std::ofstream csv;
  if (!a.csv_path.empty()) {
    csv.open(a.csv_path);
    if (!csv) {
      std::fprintf(stderr, "masa_lcm_probe: cannot write %s\n", a.csv_path.c_str());
      return 2;
    }
    csv << "channel,recv_us,utime,latency_us,bytes,version\n";
  }

  ProbeRecorder recorder(a, csv);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  if (!a.log_path.empty()) {
    try {
      if (!replayLog(a, recorder)) return 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "masa_lcm_probe: %s\n", e.what());
      return 2;
    }
    recorder.printSummary();
    return 0;
  }
  try {
    std::optional<transport::RunKey> key;
    if (!a.key_file.empty()) key = transport::readRunKey(a.key_file);
    const bool checked = key || !a.roster_file.empty();
    std::unique_ptr<transport::Transport> bus = openBus(a, key);
    if (!bus->recvBufCheck().sufficient) std::fprintf(stderr, "masa_lcm_probe: %s\n", bus->recvBufCheck().message.c_str());
    for (const std::string& ch : a.channels) {
      bus->subscribeRaw(ch, [&, ch](const void* data, int size) {
        const int64_t now = transport::wallClockMicros();  // first: decoding is not the network's time
        if (!checked) size = transport::sizeBeforeTrailer(data, size);
        recorder.record(ch, data, size, now);
      });
    }
    std::fprintf(stderr, "masa_lcm_probe: listening on %s; %s\n", a.url.c_str(),
                 key ? ("tags checked with run key id " + key->id()).c_str()
                 : !a.roster_file.empty() ? ("signatures checked against the roster " + a.roster_file).c_str()
                                          : "tags not checked (no --key-file or --roster)");
    if (!listen(a, *bus, recorder)) return 1;
    recorder.countRefusals(*bus);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_lcm_probe: %s\n", e.what());
    return 2;
  }
  recorder.printSummary();
  return 0;
}
