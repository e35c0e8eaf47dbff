// masa_deploy: runs a trained policy on a robot over LCM.
//   masa_deploy tasks/a1_beam/policy/policy.bin --config my_robot.yaml [--set watchdog.stale_after_s=0.03]
// Reads lcmt_robot_state on lcm.state_channel, publishes lcmt_robot_command on lcm.command_channel
// (configs/deploy/defaults.yaml). Refuses to start while another runner publishes commands; then
// ramps to the nominal pose, hands over to the policy, and keeps the watchdog and the limits
// (deploy/runner/policy_runner.hpp). Every ending after the start guard puts the safe command on
// the wire before the process exits (a signal: SIGINT, SIGTERM, SIGHUP; --duration; the policy step
// limit; another runner; an error in the control loop); one that cannot (SIGKILL, a crash) leaves
// the robot to its own command timeout (docs/reliability.md, "The robot's side").
// --require-signed --trusted-keys KEYS refuses a policy file not signed by one of the Ed25519 public
// keys in KEYS (a .pub file, or a directory of them; masa_seal keygen / sign make them).
// The robot channels are signed by default (issue #55, item 2): --roster ROSTER --signing-key KEY
// (masa_roster make DIR --runner --robot makes DIR/roster, DIR/keys/runner0.key and robot0.key)
// signs every command as `runner 0` of the roster, for a robot side that verifies commands
// (masa_sim_robot --roster ROSTER), and takes only state signed by robot 0 of the roster and new
// (its counter window), refusing the rest by reason (masa_sim_robot --signing-key
// DIR/keys/robot0.key). The start guard and the watch for other runners hear only commands a
// sender of the roster signed (runner 0, a new counter); the rest are refused and counted.
// --insecure is the explicit way out, for a robot whose bridge neither signs nor verifies: commands
// unsigned, state and other runners' commands heard unverified (a signer's trailer cut off), and
// the watch errs towards stopping (deploy/runner/foreign_runners.hpp). Without either, it refuses
// to start (exit 2), naming both.
// Exit codes: 0 stopped (signal, --duration, --max-policy-steps), 2 error (in the control loop:
// after the safe command), 3 start guard refused or another runner appeared (then after the safe
// command), 4 stopped by the watchdog or the emergency stop (--exit-on-trip).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <filesystem>
#include <charconv>
#include <random>
#include <sched.h>
#include <thread>
#include <vector>

#include "common/core/build_info.hpp"
#include "common/policy/policy_file.hpp"
#include "common/transport/signed_publisher.hpp"
#include "common/transport/transport.hpp"
#include "deploy/runner/deploy_config.hpp"
#include "deploy/runner/foreign_runners.hpp"
#include "deploy/runner/policy_runner.hpp"
#include "deploy/runner/realtime.hpp"

using namespace masa;

namespace {

std::atomic<int> g_signal{0};  // the signal that asked the runner to stop; 0: none
void onSignal(int sig) { g_signal = sig; }

const char* signalName(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
  }
  return "a signal";
}

int64_t steadyMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Latencies from state received to command published, in microsecond bins (the last: beyond).
class LatencyHistogram {
 public:
  void add(int64_t us) {
    ++bins_[std::clamp<int64_t>(us, 0, kBins - 1)];
    ++count_;
  }
  int64_t count() const { return count_; }
  int64_t quantile(double p) const {
    const int64_t want = static_cast<int64_t>(std::ceil(p * count_));
    int64_t seen = 0;
    for (int i = 0; i < kBins; ++i)
      if ((seen += bins_[i]) >= want && want > 0) return i;
    return 0;
  }

 private:
  static constexpr int kBins = 100000;
  std::vector<int64_t> bins_ = std::vector<int64_t>(kBins, 0);
  int64_t count_ = 0;
};

// State received (the handler) -> command published, and its parts: until poll() starts (the rest
// of the LCM dispatch, the loop), poll() (observation, inference, limits), publish().
struct CommandLatency {
  LatencyHistogram total, to_poll, in_poll, in_publish;
  void add(int64_t rx, int64_t polled, int64_t computed, int64_t out) {
    total.add(out - rx);
    to_poll.add(polled - rx);
    in_poll.add(computed - polled);
    in_publish.add(out - computed);
  }
};

// The runner's last line: the mode it stopped in and why, the states and commands counted, and the
// latency from a state's arrival to its command's publication, split by stage.
void printStopLine(const deploy::PolicyRunner& runner, const CommandLatency& latency, int64_t published,
                   int64_t rejected_states) {
  std::fprintf(stderr,
               "masa_deploy: stopped in mode %s (%s); %lld states (%lld ignored, %lld rejected by the wire guard), "
               "%lld commands, %lld policy steps; latency state received -> command published: p50 %lld us, "
               "p99 %lld us over %lld commands (until poll p50 %lld / p99 %lld us, poll %lld / %lld us, publish "
               "%lld / %lld us)\n",
               deploy::modeName(runner.mode()), runner.reason().c_str(), static_cast<long long>(runner.statesReceived()),
               static_cast<long long>(runner.statesIgnored()), static_cast<long long>(rejected_states),
               static_cast<long long>(published), static_cast<long long>(runner.policySteps()),
               static_cast<long long>(latency.total.quantile(0.5)), static_cast<long long>(latency.total.quantile(0.99)),
               static_cast<long long>(latency.total.count()), static_cast<long long>(latency.to_poll.quantile(0.5)),
               static_cast<long long>(latency.to_poll.quantile(0.99)), static_cast<long long>(latency.in_poll.quantile(0.5)),
               static_cast<long long>(latency.in_poll.quantile(0.99)), static_cast<long long>(latency.in_publish.quantile(0.5)),
               static_cast<long long>(latency.in_publish.quantile(0.99)));
}

// Waits for the loop's next piece of work: a state, or a command's deadline; with the realtime
// settings, also the warm-up before a command (realtime.warm_up_us) and, near a command, no sleep
// at all (realtime.busy_poll_us), so that no thread wakeup stands between the state and the
// command; sched_yield lets LCM's receive thread (same core, same priority) run meanwhile.
void waitForWork(transport::Transport& lcm, deploy::PolicyRunner& runner, const deploy::DeployConfig& cfg,
                 int64_t& warmed_for) {
  const int64_t now = steadyMicros();
  int64_t wait_us = std::clamp<int64_t>(runner.nextDeadline(now) - now, 0, 20000);
  const int64_t due = runner.nextCommandDueUs();
  if (cfg.warm_up_us > 0 && due != warmed_for && due != INT64_MAX) {
    if (now >= due - cfg.warm_up_us) {
      runner.warmUp();
      warmed_for = due;
      return;
    }
    wait_us = std::min(wait_us, due - cfg.warm_up_us - now);
  }
  if (cfg.busy_poll_us > 0) {
    const int64_t spin_from = due - cfg.busy_poll_us;
    if (now >= spin_from) {
      if (lcm.handleTimeout(0) > 0) lcm.drain(); else sched_yield();
      return;
    }
    wait_us = std::min(wait_us, spin_from - now);
  }
  if (lcm.handleTimeout(static_cast<int>((wait_us + 999) / 1000)) > 0) lcm.drain();
}

// The command line: what to run, on which config, and the run's limits.
struct DeployArgs {
  std::string policy_path, config_file, url;
  std::vector<std::string> sets;
  double duration_s = 0;
  int64_t max_policy_steps = 0;
  uint64_t min_policy_version = 0;
  bool quiet = false, exit_on_trip = false, require_signed = false, verify_state = false, insecure = false;
  std::string trusted_keys_path, roster_file, signing_key;
  std::string release_state;  // the newest release this robot accepted, kept across runs
};

// Parses the command line; returns an exit code when the program should end now (help, version,
// an error), or -1 to go on.
int parseArgs(int argc, char** argv, DeployArgs& a) {
  CLI::App app{"masa_deploy: run a trained policy on a robot over LCM"};
  app.set_version_flag("--version", masa::buildCommit());
  app.add_option("policy", a.policy_path, "policy file (policy.bin of a run, or a shipped one)")->required()
      ->check(CLI::ExistingFile);
  app.add_option("--config", a.config_file, "the robot's deploy config (YAML; keys of configs/deploy/defaults.yaml)");
  app.add_option("--set", a.sets, "key.path=value over the config (repeatable)");
  app.add_option("--url", a.url, "LCM provider URL (overrides lcm.url)");
  app.add_option("--duration", a.duration_s, "stop (with the safe command) after this many seconds (0: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-policy-steps", a.max_policy_steps, "hold the pose and stop after this many policy commands");
  app.add_flag("--exit-on-trip", a.exit_on_trip, "exit (code 4) once the watchdog or the emergency stop has tripped and its command is out");
  app.add_flag("--quiet", a.quiet, "no per-second status line");
  app.add_flag("--require-signed", a.require_signed, "refuse a policy file not signed by a key of --trusted-keys");
  app.add_option("--min-policy-version", a.min_policy_version,
                 "with --require-signed: refuse a policy not signed as this release or a newer one (masa_seal sign --release-version)");
  app.add_option("--release-state", a.release_state,
                 "with --require-signed: a file of the robot's that keeps the newest release it accepted; an older "
                 "one is refused from then on, without --min-policy-version (made when missing)");
  app.add_option("--trusted-keys", a.trusted_keys_path, "Ed25519 public key file (PEM), or a directory of *.pub files")
      ->check(CLI::ExistingPath);
  auto* roster_opt = app.add_option("--roster", a.roster_file,
                                    "sign every command as runner 0 of this roster and take only state signed by its "
                                    "robot 0 (masa_roster make DIR --runner --robot)");
  auto* key_opt = app.add_option("--signing-key", a.signing_key, "the runner's private key file (mode 0600), with --roster");
  roster_opt->needs(key_opt);
  key_opt->needs(roster_opt);
  auto* verify_opt = app.add_flag("--verify-state", a.verify_state, "the default with --roster (kept for earlier command lines)")
                         ->needs(roster_opt);
  app.add_flag("--insecure", a.insecure,
               "unsigned commands, unverified state: anyone on the robot's network can command the robot")
      ->excludes(roster_opt)->excludes(key_opt)->excludes(verify_opt);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (!a.insecure && a.roster_file.empty()) {
    std::fprintf(stderr, "masa_deploy: the robot channels are signed: give --roster DIR/roster --signing-key "
                         "DIR/keys/runner0.key (masa_roster make DIR --runner --robot; the robot signs with "
                         "DIR/keys/robot0.key), or --insecure for a robot that neither signs nor verifies\n");
    return 2;
  }
  a.verify_state = !a.insecure;
  if (a.require_signed != !a.trusted_keys_path.empty()) {
    std::fprintf(stderr, a.require_signed ? "masa_deploy: --require-signed needs --trusted-keys (the public keys a policy may be signed by)\n"
                                          : "masa_deploy: --trusted-keys is used with --require-signed (say both)\n");
    return 2;
  }
  if (!a.release_state.empty() && !a.require_signed) {
    std::fprintf(stderr, "masa_deploy: --release-state needs --require-signed (a release version is believed only as a trusted key signed it)\n");
    return 2;
  }
  if (a.min_policy_version > 0 && !a.require_signed) {
    std::fprintf(stderr, "masa_deploy: --min-policy-version needs --require-signed (a release version is believed only as a trusted key signed it)\n");
    return 2;
  }
  return -1;
}

// --release-state: the newest release this robot accepted (one decimal number; 0 when the file is
// missing). Anything else in it is refused: a damaged state must not lower the floor.
uint64_t readReleaseState(const std::string& path) {
  std::ifstream in(path);
  if (!in) return 0;
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  uint64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size())
    throw std::runtime_error(path + ": not a release number (--release-state keeps one): '" + text.substr(0, 40) + "'");
  return v;
}

// Written beside and renamed: a robot stopped while writing keeps the old floor, never none.
void writeReleaseState(const std::string& path, uint64_t version) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << version << '\n';
    if (!out) throw std::runtime_error(tmp + ": cannot write the release state");
  }
  std::filesystem::rename(tmp, path);
}

// The policy file, its integrity checked (and its signature, with --require-signed).
policy::LoadedPolicy loadCheckedPolicy(const DeployArgs& a) {
  integrity::TrustedKeys trusted;
  integrity::ReadRules rules;
  uint64_t accepted = 0;
  if (a.require_signed) {
    trusted = integrity::TrustedKeys::load(a.trusted_keys_path);
    rules.require_signed_by = &trusted;
    if (!a.release_state.empty()) accepted = readReleaseState(a.release_state);
    rules.min_release_version = std::max(a.min_policy_version, accepted);
  }
  policy::LoadedPolicy lp = policy::loadPolicyFile(a.policy_path, config::defaultConfigsDir(), rules);
  std::fprintf(stderr, "masa_deploy: %s: %s\n", a.policy_path.c_str(), lp.integrity.c_str());
  if (!a.release_state.empty() && lp.release && lp.release->version > accepted) {
    writeReleaseState(a.release_state, lp.release->version);
    std::fprintf(stderr, "masa_deploy: %s: release %llu is the newest this robot accepted; older ones are refused from now on\n",
                 a.release_state.c_str(), static_cast<unsigned long long>(lp.release->version));
  }
  return lp;
}

// Signed commands (the default): the key must be the one the roster gives runner 0.
std::shared_ptr<transport::MessageSigner> loadCommandSigner(const DeployArgs& a) {
  if (a.roster_file.empty()) return nullptr;
  auto signer = transport::loadSignedMode(a.roster_file, a.signing_key, {transport::Role::kRunner, 0}).signer;
  std::fprintf(stderr, "masa_deploy: commands signed as runner 0 with %s (%s), roster %s\n", a.signing_key.c_str(),
               integrity::keyFingerprint(signer->publicKey()).c_str(), a.roster_file.c_str());
  return signer;
}

// A transport that only watches: it checks every message against the roster and hands over only
// those that pass (the rest are counted by reason).
std::unique_ptr<transport::Transport> openWatcher(std::shared_ptr<const transport::Roster> roster, const std::string& url) {
  transport::SignedMode watch;
  watch.roster = std::move(roster);
  return std::make_unique<transport::Transport>(url, watch);
}

// Verified state (the default) comes through a watcher of its own.
std::unique_ptr<transport::Transport> openVerifyingTransport(const DeployArgs& a, const std::string& url) {
  if (!a.verify_state) return nullptr;
  auto roster = std::make_shared<transport::Roster>(transport::Roster::load(a.roster_file));
  if (!roster->find({transport::Role::kRobot, 0}))
    throw std::runtime_error("the roster " + a.roster_file + " names no robot 0 to take the state from (masa_roster make DIR "
                             "--robot), or --insecure");
  auto verifying = openWatcher(std::move(roster), url);
  std::fprintf(stderr, "masa_deploy: state taken only signed by robot 0 of %s\n", a.roster_file.c_str());
  return verifying;
}

// With a roster, other runners' commands are heard through a watcher too: a command that another
// runner could send counts only when a sender the roster lets command the robot signed it
// (issue #55, item 3); an unsigned or wrongly signed one is refused, counted and changes nothing.
std::unique_ptr<transport::Transport> openCommandWatcher(const DeployArgs& a, const std::string& url,
                                                         const std::string& channel) {
  if (a.roster_file.empty()) return nullptr;
  auto watcher = openWatcher(std::make_shared<transport::Roster>(transport::Roster::load(a.roster_file)), url);
  std::fprintf(stderr, "masa_deploy: other runners' commands on %s heard only signed by a sender of %s\n",
               channel.c_str(), a.roster_file.c_str());
  return watcher;
}

void printStartLine(const policy::LoadedPolicy& lp, double sym_error, const deploy::PolicyRunner& runner,
                    const deploy::DeployConfig& cfg, int64_t runner_id, const std::string& scheduling) {
  std::fprintf(stderr,
               "masa_deploy: task %s, method %s (equivariance error %.1e), %d joints, %.1f Hz, watchdog %.0f ms "
               "(safe command within %.0f ms), state %s, commands %s, id %lld; %s%s\n",
               lp.config.task.c_str(), model::methodName(lp.config.method).c_str(), sym_error, runner.numJoints(),
               1.0 / runner.periodS(), cfg.stale_after_s * 1e3, runner.watchdogBoundS() * 1e3, cfg.state_channel.c_str(),
               cfg.command_channel.c_str(), static_cast<long long>(runner_id), scheduling.c_str(),
               (std::string(cfg.busy_poll_us > 0 ? "; busy poll " + std::to_string(cfg.busy_poll_us) + " us" : "") +
                (cfg.warm_up_us > 0 ? "; warm-up " + std::to_string(cfg.warm_up_us) + " us" : "") +
                (cfg.busy_poll_us > 0 || cfg.warm_up_us > 0 ? " before each command" : ""))
                   .c_str());
}

// The runner's transports and what they have heard.
struct Links {
  transport::Transport& lcm;             // commands out; other runners' commands in, without a roster
  transport::Transport* verifying;       // verified state in (--verify-state), else null
  transport::Transport* command_watcher;  // other runners' commands in, verified (--roster), else null
  transport::SignedPublisher& commands;  // signs each command when a signer is given
  deploy::ForeignRunners foreign;
  int64_t rejected_states = 0;           // states refused by the wire guard
  transport::Transport& stateIn() { return verifying ? *verifying : lcm; }
  // Handles what is queued on the transports the loop does not wait on.
  void drainOthers() {
    if (verifying) lcm.drain();
    if (command_watcher) command_watcher->drain();
  }
};

// Why the run ends, and how: the exit code, the reason the log and the last command give, and
// the mode of the safe command that goes out before the process exits.
struct RunEnd {
  int exit_code = 0;
  std::string why;  // empty: the run goes on
  deploy::Mode safe = deploy::Mode::kDamping;
  bool at_once = true;  // false: at the next command's due time (the last policy command keeps its period)
  bool ended() const { return !why.empty(); }
};

RunEnd whyEnd(const DeployArgs& a, const deploy::DeployConfig& cfg, const deploy::PolicyRunner& runner,
              const Links& links, int64_t elapsed_us) {
  if (const int sig = g_signal.load()) return {0, std::string("stopped by ") + signalName(sig), runner.safeMode()};
  if (links.foreign.heard() > 0)
    return {3, "another runner (id " + std::to_string(links.foreign.lastId()) + ") publishes on " + cfg.command_channel,
            runner.safeMode()};
  if (a.duration_s > 0 && elapsed_us >= static_cast<int64_t>(a.duration_s * 1e6))
    return {0, "--duration reached", runner.safeMode()};
  if (a.max_policy_steps > 0 && runner.policySteps() >= a.max_policy_steps)
    return {0, "policy step limit reached", deploy::Mode::kHold, false};
  return {};
}

// The last line before the exit: what the robot was left with.
void printExitLine(const RunEnd& end, const deploy::PolicyRunner& runner, bool safe_sent) {
  if (safe_sent)
    std::fprintf(stderr, "masa_deploy: exit %d: %s; the last command sent was the safe command (%s)\n", end.exit_code,
                 end.why.c_str(), deploy::modeName(runner.mode()));
  else if (!runner.hasState())
    std::fprintf(stderr, "masa_deploy: exit %d: %s; no robot state was heard, so no command was sent (nothing to make safe)\n",
                 end.exit_code, end.why.c_str());
  else
    std::fprintf(stderr, "masa_deploy: exit %d: %s; the safe command could NOT be sent: the robot's command timeout "
                 "must make it safe\n", end.exit_code, end.why.c_str());
}

// The control loop: state in, command out, until an ending (whyEnd) or a latched trip with
// --exit-on-trip. Returns the run's end; safe_sent says whether LCM took its safe command.
RunEnd controlLoop(const DeployArgs& a, const deploy::DeployConfig& cfg, deploy::PolicyRunner& runner, Links& links,
                   masa::lcmt_robot_command& cmd, CommandLatency& latency, int64_t& published, bool& safe_sent) {
  deploy::Mode shown = deploy::Mode::kCalibrating;
  bool announced = false;
  const int64_t t0 = steadyMicros();
  int64_t next_status = t0 + 1000000, warmed_for = -1;
  RunEnd end;
  for (;;) {
    const int64_t now = steadyMicros();
    if (!end.ended() && (end = whyEnd(a, cfg, runner, links, now - t0)).ended()) {
      if (!runner.hasState()) return end;  // no robot heard: nothing to make safe
      if (end.at_once) runner.stopNow(end.safe, end.why); else runner.stop(end.safe, end.why);
    }
    if (runner.poll(now, cmd)) {
      const int64_t computed = steadyMicros();
      const bool out = links.commands.publish(cfg.command_channel, cmd);
      ++published;
      if (runner.lastAnsweredRxUs() > 0) latency.add(runner.lastAnsweredRxUs(), now, computed, steadyMicros());
      if (!announced || runner.mode() != shown) {
        std::fprintf(stderr, "masa_deploy: %s: %s\n", deploy::modeName(runner.mode()), runner.reason().c_str());
        shown = runner.mode();
        announced = true;
      }
      if (deploy::isLatched(runner.mode()) && (end.ended() || a.exit_on_trip)) {
        safe_sent = out;
        if (!end.ended()) end = {4, runner.reason(), runner.mode()};
        return end;
      }
    }
    if (!a.quiet && now >= next_status) {
      std::fprintf(stderr, "masa_deploy: %.0f s, %s, %lld states, %lld commands, %lld policy steps\n", (now - t0) * 1e-6,
                   deploy::modeName(runner.mode()), static_cast<long long>(runner.statesReceived()),
                   static_cast<long long>(published), static_cast<long long>(runner.policySteps()));
      next_status += 1000000;
    }
    // The state wakes the runner; the other runners' commands (on lcm or the watcher) are read between.
    waitForWork(links.stateIn(), runner, cfg, warmed_for);
    links.drainOthers();
  }
}

// After an error in the control loop: the safe command at once, if a robot was heard.
bool sendSafeCommandAfterError(const deploy::DeployConfig& cfg, deploy::PolicyRunner& runner, Links& links,
                               masa::lcmt_robot_command& cmd, const std::string& why) {
  if (!runner.hasState()) return false;
  try {
    runner.stopNow(runner.safeMode(), why);
    return runner.poll(steadyMicros(), cmd) && links.commands.publish(cfg.command_channel, cmd);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_deploy: the safe command failed too: %s\n", e.what());
    return false;
  }
}

// The control loop and everything that ends it; returns the exit code.
int runControlLoop(const DeployArgs& a, const deploy::DeployConfig& cfg, deploy::PolicyRunner& runner, Links& links) {
  masa::lcmt_robot_command cmd = runner.makeCommand();
  CommandLatency latency;
  int64_t published = 0;
  bool safe_sent = false;
  RunEnd end;
  try {
    end = controlLoop(a, cfg, runner, links, cmd, latency, published, safe_sent);
  } catch (const std::exception& e) {
    end = {2, std::string("error: ") + e.what(), runner.safeMode()};
    std::fprintf(stderr, "masa_deploy: %s\n", end.why.c_str());
    safe_sent = sendSafeCommandAfterError(cfg, runner, links, cmd, end.why);
    if (safe_sent) ++published;
  }
  printStopLine(runner, latency, published, links.rejected_states);
  if (links.verifying)
    std::fprintf(stderr, "masa_deploy: state refused before decoding: %s\n", links.verifying->rejectSummary().c_str());
  if (links.command_watcher)
    std::fprintf(stderr, "masa_deploy: commands refused before decoding: %s\n", links.command_watcher->rejectSummary().c_str());
  if (links.foreign.undecodable() > 0)
    std::fprintf(stderr, "masa_deploy: %lld messages on %s refused by the wire guard\n",
                 static_cast<long long>(links.foreign.undecodable()), cfg.command_channel.c_str());
  printExitLine(end, runner, safe_sent);
  return end.exit_code;
}

}  // namespace

int main(int argc, char** argv) {
  DeployArgs a;
  if (const int code = parseArgs(argc, argv, a); code >= 0) return code;
  // SIGHUP: the terminal or ssh session that started the runner went away. SIGPIPE ignored: a
  // closed stderr must not kill the runner before its safe command.
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, onSignal);
  std::signal(SIGPIPE, SIG_IGN);

  try {
    const deploy::DeployConfig cfg = deploy::loadDeployConfig(a.config_file, a.sets);
    const std::string url = a.url.empty() ? cfg.lcm_url : a.url;
    policy::LoadedPolicy lp = loadCheckedPolicy(a);
    const double sym_error = policy::checkPolicySymmetry(lp);
    std::random_device rd;
    const int64_t runner_id = static_cast<int64_t>((uint64_t{rd()} << 32) ^ rd() ^ steadyMicros()) & INT64_MAX;
    deploy::PolicyRunner runner(lp, cfg, runner_id);
    const std::string scheduling = deploy::applyRealtime(cfg.realtime);  // before LCM starts its receive thread
    transport::Transport lcm(url);
    transport::SignedPublisher commands(lcm, loadCommandSigner(a));
    std::unique_ptr<transport::Transport> verifying = openVerifyingTransport(a, url);
    std::unique_ptr<transport::Transport> command_watcher = openCommandWatcher(a, url, cfg.command_channel);
    printStartLine(lp, sym_error, runner, cfg, runner_id, scheduling);
    if (a.insecure)
      std::fprintf(stderr, "masa_deploy: --insecure: commands unsigned, state and other runners' commands unverified: "
                           "anyone who can publish on %s commands the robot with any gains and targets, and any state "
                           "reaches the policy\n",
                   cfg.command_channel.c_str());

    Links links{lcm, verifying.get(), command_watcher.get(), commands, {}, 0};
    links.foreign.listen(command_watcher ? *command_watcher : lcm, cfg.command_channel, runner.makeCommand(), runner_id);
    masa::lcmt_robot_state state{};
    state.joint_position.reserve(runner.numJoints());
    state.joint_velocity.reserve(runner.numJoints());
    state.joint_torque.reserve(runner.numJoints());
    links.stateIn().subscribeRaw(cfg.state_channel, [&](const void* data, int size) {
      const int64_t rx = steadyMicros();
      // --insecure: a signing robot's trailer is not part of the state (verified: already cut off).
      if (!verifying) size = transport::sizeWithoutSigTrailer(data, size);
      if (transport::decodeChecked(data, size, state) != transport::WireVerdict::kOk) {
        ++links.rejected_states;
        return;
      }
      runner.onState(state, rx);
    });

    // Before the guard has passed, this runner has sent nothing and the robot is not its own: an
    // ending here sends nothing either (a safe command now would be a second runner's command).
    const int64_t guard_end = steadyMicros() + static_cast<int64_t>(cfg.start_guard_s * 1e6);
    while (steadyMicros() < guard_end && !g_signal) {
      lcm.handleTimeout(10);
      if (verifying) verifying->drain();
      if (command_watcher) command_watcher->drain();
    }
    if (links.foreign.heard() > 0) {
      std::fprintf(stderr, "masa_deploy: REFUSED: another runner (id %lld) publishes on %s; stop it first (no command sent)\n",
                   static_cast<long long>(links.foreign.lastId()), cfg.command_channel.c_str());
      return 3;
    }
    if (const int sig = g_signal.load()) {
      std::fprintf(stderr, "masa_deploy: stopped by %s during the start guard; no command sent\n", signalName(sig));
      return 0;
    }
    std::fprintf(stderr, "masa_deploy: start guard passed (%.2f s, no other runner); waiting for state on %s\n",
                 cfg.start_guard_s, cfg.state_channel.c_str());
    return runControlLoop(a, cfg, runner, links);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_deploy: %s\n", e.what());
    return 2;
  }
}
