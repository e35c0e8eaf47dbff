// masa_deploy: runs a trained policy on a robot over LCM.
//   masa_deploy tasks/a1_beam/policy/policy.bin --config my_robot.yaml [--set watchdog.stale_after_s=0.03]
// Reads lcmt_robot_state on lcm.state_channel, publishes lcmt_robot_command on lcm.command_channel
// (configs/deploy/defaults.yaml). Refuses to start while another runner publishes commands; then
// ramps to the nominal pose, hands over to the policy, and keeps the watchdog and the limits
// (deploy/runner/policy_runner.hpp). Ctrl-C publishes the safe command before it exits.
// --require-signed --trusted-keys KEYS refuses a policy file not signed by one of the Ed25519 public
// keys in KEYS (a .pub file, or a directory of them; masa_seal keygen / sign make them).
// --roster ROSTER --signing-key KEY signs every command as `runner 0` of the roster (masa_roster make
// DIR --runner makes DIR/roster and DIR/keys/runner0.key), for a robot side that verifies commands
// (masa_sim_robot --roster ROSTER). --verify-state (with --roster) takes only state signed by robot 0
// of the roster and new (its counter window), refusing the rest by reason (masa_roster make DIR
// --robot; masa_sim_robot --signing-key DIR/keys/robot0.key); without it the state is read unsigned.
// Either way the start guard hears every runner's commands, signed or not, unverified: it errs
// towards refusing to start.
// Exit codes: 0 stopped (signal, --duration, --max-policy-steps), 2 error, 3 start guard refused or
// another runner appeared, 4 stopped by the watchdog or the emergency stop (--exit-on-trip).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <random>
#include <sched.h>
#include <thread>
#include <vector>

#include "common/core/build_info.hpp"
#include "common/policy/policy_file.hpp"
#include "common/transport/signed_publisher.hpp"
#include "common/transport/transport.hpp"
#include "deploy/runner/deploy_config.hpp"
#include "deploy/runner/policy_runner.hpp"
#include "deploy/runner/realtime.hpp"

using namespace masa;

namespace {

std::atomic<bool> g_stop{false};
void onSignal(int) { g_stop = true; }

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
  bool quiet = false, exit_on_trip = false, require_signed = false, verify_state = false;
  std::string trusted_keys_path, roster_file, signing_key;
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
  app.add_option("--trusted-keys", a.trusted_keys_path, "Ed25519 public key file (PEM), or a directory of *.pub files")
      ->check(CLI::ExistingPath);
  auto* roster_opt = app.add_option("--roster", a.roster_file,
                                    "sign every command as runner 0 of this roster (masa_roster make DIR --runner), for "
                                    "a robot side that verifies commands");
  auto* key_opt = app.add_option("--signing-key", a.signing_key, "the runner's private key file (mode 0600), with --roster");
  roster_opt->needs(key_opt);
  key_opt->needs(roster_opt);
  app.add_flag("--verify-state", a.verify_state,
               "take only state messages signed by robot 0 of --roster (masa_roster make DIR --robot), refuse the rest")
      ->needs(roster_opt);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (a.require_signed != !a.trusted_keys_path.empty()) {
    std::fprintf(stderr, a.require_signed ? "masa_deploy: --require-signed needs --trusted-keys (the public keys a policy may be signed by)\n"
                                          : "masa_deploy: --trusted-keys is used with --require-signed (say both)\n");
    return 2;
  }
  return -1;
}

// The policy file, its integrity checked (and its signature, with --require-signed).
policy::LoadedPolicy loadCheckedPolicy(const DeployArgs& a) {
  integrity::TrustedKeys trusted;
  integrity::ReadRules rules;
  if (a.require_signed) {
    trusted = integrity::TrustedKeys::load(a.trusted_keys_path);
    rules.require_signed_by = &trusted;
  }
  policy::LoadedPolicy lp = policy::loadPolicyFile(a.policy_path, config::defaultConfigsDir(), rules);
  std::fprintf(stderr, "masa_deploy: %s: %s\n", a.policy_path.c_str(), lp.integrity.c_str());
  return lp;
}

// Signed commands (opt-in): the key must be the one the roster gives runner 0.
std::shared_ptr<transport::MessageSigner> loadCommandSigner(const DeployArgs& a) {
  if (a.roster_file.empty()) return nullptr;
  auto signer = transport::loadSignedMode(a.roster_file, a.signing_key, {transport::Role::kRunner, 0}).signer;
  std::fprintf(stderr, "masa_deploy: commands signed as runner 0 with %s (%s), roster %s\n", a.signing_key.c_str(),
               integrity::keyFingerprint(signer->publicKey()).c_str(), a.roster_file.c_str());
  return signer;
}

// Verified state (opt-in) comes through a transport of its own that checks every message against
// the roster; the command channel stays on the plain transport, unverified, for the start guard.
std::unique_ptr<transport::Transport> openVerifyingTransport(const DeployArgs& a, const std::string& url) {
  if (!a.verify_state) return nullptr;
  transport::SignedMode watch;
  watch.roster = std::make_shared<transport::Roster>(transport::Roster::load(a.roster_file));
  if (!watch.roster->find({transport::Role::kRobot, 0}))
    throw std::runtime_error("--verify-state: the roster " + a.roster_file + " names no robot 0 (masa_roster make DIR --robot)");
  auto verifying = std::make_unique<transport::Transport>(url, watch);
  std::fprintf(stderr, "masa_deploy: state taken only signed by robot 0 of %s\n", a.roster_file.c_str());
  return verifying;
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

// Commands of other runners on our channel, heard unverified (another runner may sign or not):
// the start guard errs towards refusing, and a runner that appears later stops this one.
struct ForeignRunners {
  int64_t count = 0, last_id = 0;
  void listen(transport::Transport& lcm, const std::string& channel, const deploy::PolicyRunner& runner, int64_t own_id) {
    heard_ = runner.makeCommand();
    lcm.subscribeRaw(channel, [this, own_id](const void* data, int size) {
      size = transport::sizeWithoutSigTrailer(data, size);
      if (transport::decodeChecked(data, size, heard_) == transport::WireVerdict::kOk && heard_.runner_id != own_id) {
        ++count;
        last_id = heard_.runner_id;
      }
    });
  }

 private:
  masa::lcmt_robot_command heard_;
};

// The runner's transports and what they have heard.
struct Links {
  transport::Transport& lcm;             // commands out; other runners' commands in
  transport::Transport* verifying;       // verified state in (--verify-state), else null
  transport::SignedPublisher& commands;  // signs each command when a signer is given
  ForeignRunners foreign;
  int64_t rejected_states = 0;           // states refused by the wire guard
  transport::Transport& stateIn() { return verifying ? *verifying : lcm; }
};

// The control loop: state in, command out, until a signal, --duration, --max-policy-steps, a
// latched trip with --exit-on-trip, or another runner. Returns the exit code.
int runControlLoop(const DeployArgs& a, const deploy::DeployConfig& cfg, deploy::PolicyRunner& runner, Links& links) {
  masa::lcmt_robot_command cmd = runner.makeCommand();
  CommandLatency latency;
  deploy::Mode shown = deploy::Mode::kCalibrating;
  bool announced = false;
  const int64_t t0 = steadyMicros();
  int64_t next_status = t0 + 1000000, published = 0, warmed_for = -1;
  int exit_code = 0;
  for (;;) {
    const int64_t now = steadyMicros();
    const bool end_by_time = a.duration_s > 0 && now - t0 >= static_cast<int64_t>(a.duration_s * 1e6);
    const bool end_by_steps = a.max_policy_steps > 0 && runner.policySteps() >= a.max_policy_steps;
    if ((g_stop || end_by_time) && !runner.hasState()) break;  // no robot heard: nothing to make safe
    if (g_stop || end_by_time || end_by_steps) {
      runner.stop(end_by_steps ? deploy::Mode::kHold : cfg.safe_mode == deploy::SafeMode::kHold ? deploy::Mode::kHold : deploy::Mode::kDamping,
                  g_stop ? "stopped by signal" : end_by_steps ? "policy step limit reached" : "--duration reached");
    }
    if (runner.poll(now, cmd)) {
      const int64_t computed = steadyMicros();
      links.commands.publish(cfg.command_channel, cmd);
      ++published;
      if (runner.lastAnsweredRxUs() > 0) latency.add(runner.lastAnsweredRxUs(), now, computed, steadyMicros());
      if (!announced || runner.mode() != shown) {
        std::fprintf(stderr, "masa_deploy: %s: %s\n", deploy::modeName(runner.mode()), runner.reason().c_str());
        shown = runner.mode();
        announced = true;
      }
      if (deploy::isLatched(runner.mode()) && (g_stop || end_by_time || end_by_steps)) break;
      if (a.exit_on_trip && deploy::isLatched(runner.mode())) {
        exit_code = 4;
        break;
      }
    }
    if (links.foreign.count > 0) {
      std::fprintf(stderr, "masa_deploy: another runner (id %lld) publishes on %s: stopping\n",
                   static_cast<long long>(links.foreign.last_id), cfg.command_channel.c_str());
      exit_code = 3;
      break;
    }
    if (!a.quiet && now >= next_status) {
      std::fprintf(stderr, "masa_deploy: %.0f s, %s, %lld states, %lld commands, %lld policy steps\n", (now - t0) * 1e-6,
                   deploy::modeName(runner.mode()), static_cast<long long>(runner.statesReceived()),
                   static_cast<long long>(published), static_cast<long long>(runner.policySteps()));
      next_status += 1000000;
    }
    // The state wakes the runner; the other runners' commands (on lcm) are read between.
    waitForWork(links.stateIn(), runner, cfg, warmed_for);
    if (links.verifying) links.lcm.drain();
  }
  printStopLine(runner, latency, published, links.rejected_states);
  if (links.verifying)
    std::fprintf(stderr, "masa_deploy: state refused before decoding: %s\n", links.verifying->rejectSummary().c_str());
  return exit_code;
}

}  // namespace

int main(int argc, char** argv) {
  DeployArgs a;
  if (const int code = parseArgs(argc, argv, a); code >= 0) return code;
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);

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
    printStartLine(lp, sym_error, runner, cfg, runner_id, scheduling);

    Links links{lcm, verifying.get(), commands, {}, 0};
    links.foreign.listen(lcm, cfg.command_channel, runner, runner_id);
    masa::lcmt_robot_state state{};
    state.joint_position.reserve(runner.numJoints());
    state.joint_velocity.reserve(runner.numJoints());
    state.joint_torque.reserve(runner.numJoints());
    links.stateIn().subscribeRaw(cfg.state_channel, [&](const void* data, int size) {
      const int64_t rx = steadyMicros();
      if (transport::decodeChecked(data, size, state) != transport::WireVerdict::kOk) {
        ++links.rejected_states;
        return;
      }
      runner.onState(state, rx);
    });

    const int64_t guard_end = steadyMicros() + static_cast<int64_t>(cfg.start_guard_s * 1e6);
    while (steadyMicros() < guard_end && !g_stop) {
      lcm.handleTimeout(10);
      if (verifying) verifying->drain();
    }
    if (links.foreign.count > 0) {
      std::fprintf(stderr, "masa_deploy: REFUSED: another runner (id %lld) publishes on %s; stop it first\n",
                   static_cast<long long>(links.foreign.last_id), cfg.command_channel.c_str());
      return 3;
    }
    std::fprintf(stderr, "masa_deploy: start guard passed (%.2f s, no other runner); waiting for state on %s\n",
                 cfg.start_guard_s, cfg.state_channel.c_str());
    return runControlLoop(a, cfg, runner, links);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_deploy: %s\n", e.what());
    return 2;
  }
}
