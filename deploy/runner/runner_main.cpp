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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"masa_deploy: run a trained policy on a robot over LCM"};
  app.set_version_flag("--version", masa::buildCommit());
  std::string policy_path, config_file, url;
  std::vector<std::string> sets;
  double duration_s = 0;
  int64_t max_policy_steps = 0;
  bool quiet = false, exit_on_trip = false, require_signed = false;
  std::string trusted_keys_path;
  app.add_option("policy", policy_path, "policy file (policy.bin of a run, or a shipped one)")->required()
      ->check(CLI::ExistingFile);
  app.add_option("--config", config_file, "the robot's deploy config (YAML; keys of configs/deploy/defaults.yaml)");
  app.add_option("--set", sets, "key.path=value over the config (repeatable)");
  app.add_option("--url", url, "LCM provider URL (overrides lcm.url)");
  app.add_option("--duration", duration_s, "stop (with the safe command) after this many seconds (0: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-policy-steps", max_policy_steps, "hold the pose and stop after this many policy commands");
  app.add_flag("--exit-on-trip", exit_on_trip, "exit (code 4) once the watchdog or the emergency stop has tripped and its command is out");
  app.add_flag("--quiet", quiet, "no per-second status line");
  app.add_flag("--require-signed", require_signed, "refuse a policy file not signed by a key of --trusted-keys");
  app.add_option("--trusted-keys", trusted_keys_path, "Ed25519 public key file (PEM), or a directory of *.pub files")
      ->check(CLI::ExistingPath);
  std::string roster_file, signing_key;
  auto* roster_opt = app.add_option("--roster", roster_file,
                                    "sign every command as runner 0 of this roster (masa_roster make DIR --runner), for "
                                    "a robot side that verifies commands");
  auto* key_opt = app.add_option("--signing-key", signing_key, "the runner's private key file (mode 0600), with --roster");
  roster_opt->needs(key_opt);
  key_opt->needs(roster_opt);
  bool verify_state = false;
  app.add_flag("--verify-state", verify_state,
               "take only state messages signed by robot 0 of --roster (masa_roster make DIR --robot), refuse the rest")
      ->needs(roster_opt);
  CLI11_PARSE(app, argc, argv);
  if (require_signed != !trusted_keys_path.empty()) {
    std::fprintf(stderr, require_signed ? "masa_deploy: --require-signed needs --trusted-keys (the public keys a policy may be signed by)\n"
                                        : "masa_deploy: --trusted-keys is used with --require-signed (say both)\n");
    return 2;
  }
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);

  try {
    const deploy::DeployConfig cfg = deploy::loadDeployConfig(config_file, sets);
    integrity::TrustedKeys trusted;
    integrity::ReadRules rules;
    if (require_signed) {
      trusted = integrity::TrustedKeys::load(trusted_keys_path);
      rules.require_signed_by = &trusted;
    }
    policy::LoadedPolicy lp = policy::loadPolicyFile(policy_path, config::defaultConfigsDir(), rules);
    std::fprintf(stderr, "masa_deploy: %s: %s\n", policy_path.c_str(), lp.integrity.c_str());
    const double sym_error = policy::checkPolicySymmetry(lp);
    std::random_device rd;
    const int64_t runner_id = static_cast<int64_t>((uint64_t{rd()} << 32) ^ rd() ^ steadyMicros()) & INT64_MAX;
    deploy::PolicyRunner runner(lp, cfg, runner_id);
    const std::string scheduling = deploy::applyRealtime(cfg.realtime);  // before LCM starts its receive thread
    transport::Transport lcm(url.empty() ? cfg.lcm_url : url);
    // Signed commands (opt-in): the key must be the one the roster gives runner 0.
    std::shared_ptr<transport::MessageSigner> signer;
    if (!roster_file.empty()) {
      signer = transport::loadSignedMode(roster_file, signing_key, {transport::Role::kRunner, 0}).signer;
      std::fprintf(stderr, "masa_deploy: commands signed as runner 0 with %s (%s), roster %s\n", signing_key.c_str(),
                   integrity::keyFingerprint(signer->publicKey()).c_str(), roster_file.c_str());
    }
    transport::SignedPublisher commands(lcm, signer);
    // Verified state (opt-in) comes through a transport of its own that checks every message
    // against the roster; the command channel stays on `lcm`, unverified, for the start guard.
    std::unique_ptr<transport::Transport> verifying;
    if (verify_state) {
      transport::SignedMode watch;
      watch.roster = std::make_shared<transport::Roster>(transport::Roster::load(roster_file));
      if (!watch.roster->find({transport::Role::kRobot, 0}))
        throw std::runtime_error("--verify-state: the roster " + roster_file + " names no robot 0 (masa_roster make DIR --robot)");
      verifying = std::make_unique<transport::Transport>(url.empty() ? cfg.lcm_url : url, watch);
      std::fprintf(stderr, "masa_deploy: state taken only signed by robot 0 of %s\n", roster_file.c_str());
    }
    transport::Transport& state_in = verifying ? *verifying : lcm;
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

    // Commands of other runners on our channel: the start guard, and a warning later.
    masa::lcmt_robot_command heard = runner.makeCommand();
    int64_t foreign = 0, foreign_id = 0;
    lcm.subscribeRaw(cfg.command_channel, [&](const void* data, int size) {
      // Signed or not (another runner may sign): unverified, the start guard errs towards refusing.
      size = transport::sizeWithoutSigTrailer(data, size);
      if (transport::decodeChecked(data, size, heard) == transport::WireVerdict::kOk && heard.runner_id != runner_id) {
        ++foreign;
        foreign_id = heard.runner_id;
      }
    });
    masa::lcmt_robot_state state{};
    state.joint_position.reserve(runner.numJoints());
    state.joint_velocity.reserve(runner.numJoints());
    state.joint_torque.reserve(runner.numJoints());
    int64_t rejected_states = 0;
    state_in.subscribeRaw(cfg.state_channel, [&](const void* data, int size) {
      const int64_t rx = steadyMicros();
      if (transport::decodeChecked(data, size, state) != transport::WireVerdict::kOk) {
        ++rejected_states;
        return;
      }
      runner.onState(state, rx);
    });

    const int64_t guard_end = steadyMicros() + static_cast<int64_t>(cfg.start_guard_s * 1e6);
    while (steadyMicros() < guard_end && !g_stop) {
      lcm.handleTimeout(10);
      if (verifying) verifying->drain();
    }
    if (foreign > 0) {
      std::fprintf(stderr, "masa_deploy: REFUSED: another runner (id %lld) publishes on %s; stop it first\n",
                   static_cast<long long>(foreign_id), cfg.command_channel.c_str());
      return 3;
    }
    std::fprintf(stderr, "masa_deploy: start guard passed (%.2f s, no other runner); waiting for state on %s\n",
                 cfg.start_guard_s, cfg.state_channel.c_str());

    masa::lcmt_robot_command cmd = runner.makeCommand();
    CommandLatency latency;
    deploy::Mode shown = deploy::Mode::kCalibrating;
    bool announced = false;
    const int64_t t0 = steadyMicros();
    int64_t next_status = t0 + 1000000, published = 0, warmed_for = -1;
    int exit_code = 0;
    for (;;) {
      const int64_t now = steadyMicros();
      const bool end_by_time = duration_s > 0 && now - t0 >= static_cast<int64_t>(duration_s * 1e6);
      const bool end_by_steps = max_policy_steps > 0 && runner.policySteps() >= max_policy_steps;
      if ((g_stop || end_by_time) && !runner.hasState()) break;  // no robot heard: nothing to make safe
      if (g_stop || end_by_time || end_by_steps) {
        runner.stop(end_by_steps ? deploy::Mode::kHold : cfg.safe_mode == deploy::SafeMode::kHold ? deploy::Mode::kHold : deploy::Mode::kDamping,
                    g_stop ? "stopped by signal" : end_by_steps ? "policy step limit reached" : "--duration reached");
      }
      if (runner.poll(now, cmd)) {
        const int64_t computed = steadyMicros();
        commands.publish(cfg.command_channel, cmd);
        ++published;
        if (runner.lastAnsweredRxUs() > 0) latency.add(runner.lastAnsweredRxUs(), now, computed, steadyMicros());
        if (!announced || runner.mode() != shown) {
          std::fprintf(stderr, "masa_deploy: %s: %s\n", deploy::modeName(runner.mode()), runner.reason().c_str());
          shown = runner.mode();
          announced = true;
        }
        if (deploy::isLatched(runner.mode()) && (g_stop || end_by_time || end_by_steps)) break;
        if (exit_on_trip && deploy::isLatched(runner.mode())) {
          exit_code = 4;
          break;
        }
      }
      if (foreign > 0) {
        std::fprintf(stderr, "masa_deploy: another runner (id %lld) publishes on %s: stopping\n",
                     static_cast<long long>(foreign_id), cfg.command_channel.c_str());
        exit_code = 3;
        break;
      }
      if (!quiet && now >= next_status) {
        std::fprintf(stderr, "masa_deploy: %.0f s, %s, %lld states, %lld commands, %lld policy steps\n", (now - t0) * 1e-6,
                     deploy::modeName(runner.mode()), static_cast<long long>(runner.statesReceived()),
                     static_cast<long long>(published), static_cast<long long>(runner.policySteps()));
        next_status += 1000000;
      }
      // The state wakes the runner; the other runners' commands (on lcm) are read between.
      waitForWork(state_in, runner, cfg, warmed_for);
      if (verifying) lcm.drain();
    }
    printStopLine(runner, latency, published, rejected_states);
    if (verifying) std::fprintf(stderr, "masa_deploy: state refused before decoding: %s\n", verifying->rejectSummary().c_str());
    return exit_code;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_deploy: %s\n", e.what());
    return 2;
  }
}
