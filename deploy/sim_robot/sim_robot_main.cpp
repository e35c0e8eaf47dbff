// masa_sim_robot: a task's robot in MuJoCo, stepped in real time, that talks LCM like a robot:
// it publishes lcmt_robot_state and applies the newest lcmt_robot_command with a PD law at every
// physics step (torque = kp (position - q) + kd (velocity - qdot) + torque_ff, clipped to the
// actuator's range), optionally with command delay, jitter and loss of either message (one seeded
// generator). The robot hangs still (physics paused, state published) until the first command.
// Once commands stop arriving for --command-timeout-ms (150 ms), it damps itself (kp 0, kd
// --damping-kd) instead of holding the last targets, and no longer follows the runner that went
// quiet; a new runner takes over (deploy/sim_robot/command_timeout.hpp).
//   masa_sim_robot tasks/a1_beam/policy/policy.bin --seed 0 --duration 12
// A robot that is not the model (issue #52, item 2): --perturb KEY=VALUE (repeatable) and
// --perturb-file FILE take env.randomization's keys, fixed values or ranges drawn from --seed
// (deploy/sim_robot/perturbation.hpp); the robot prints what it drew, read back from its model:
//   masa_sim_robot POLICY --insecure --perturb env.randomization.mass_scale=1.2 --perturb actuator_strength=0.85
// At the end it prints the task's progress figures over the policy phase (commands in mode 1)
// and whether the task's termination test fired (a fall). Fault injection for tests:
// --stop-state-after S stops publishing state, --nan-state-after S publishes NaN joint angles;
// both report when the first safe command (mode >= 2) arrived after the fault; --tilt-state-after S
// reports the base rolled by --tilt-rad more than it is (an IMU's view of a fall), and the robot
// then reports its final joint angles and the fastest target change between emergency-stop commands.
// Signed by default (issue #55, item 2): --roster ROSTER --signing-key DIR/keys/robot0.key
// (masa_roster make DIR --runner --robot). It takes a command only when it is signed by a sender the
// roster lets publish on the command channel (runner 0; masa_deploy --roster --signing-key) and is
// new (counter window); others are refused and counted by reason, printed at the end. Every state
// message is signed as robot 0, for the runner, which verifies it. --insecure instead: commands
// taken signed or not (the trailer cut off unverified), state unsigned. Without either it refuses
// to start (exit 2).
// A command whose utime is ahead of the robot's wall clock by more than --command-lead-ms (100 ms)
// is refused and counted (ahead_of_clock): the newest command wins, so one stamped far in the future
// would pin the robot (deploy/sim_robot/command_lead.hpp).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "common/core/build_info.hpp"
#include "common/policy/policy_file.hpp"
#include "common/sim/registry.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/signed_publisher.hpp"
#include "common/transport/transport.hpp"
#include "deploy/sim_robot/command_lead.hpp"
#include "deploy/sim_robot/command_link.hpp"
#include "deploy/sim_robot/command_timeout.hpp"
#include "deploy/sim_robot/perturbation.hpp"
#include "deploy/sim_robot/run_record.hpp"
#include "deploy/sim_robot/sim_robot.hpp"
#include "masa/lcmt_robot_command.hpp"
#include "masa/lcmt_robot_state.hpp"
#include "tasks/tasks.hpp"

using namespace masa;
using Clock = std::chrono::steady_clock;

namespace {

std::atomic<bool> g_stop{false};
void onSignal(int) { g_stop = true; }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"masa_sim_robot: a task's robot in MuJoCo, in real time, over LCM"};
  app.set_version_flag("--version", masa::buildCommit());
  std::string policy_path, url, state_channel = transport::kRobotStateChannel,
                                command_channel = transport::kRobotCommandChannel;
  uint64_t seed = 0, fault_seed = 1;
  double duration = 10, delay_ms = 0, jitter_ms = 0, loss = 0, stop_state_after = -1, nan_state_after = -1;
  double tilt_state_after = -1, tilt_rad = 1.0;
  int state_every = 1;
  bool quiet = false;
  double command_timeout_ms = 150, damping_kd = 2.0, command_lead_ms = 100;
  app.add_option("policy", policy_path, "policy file: its task is built exactly as trained")->required()->check(CLI::ExistingFile);
  app.add_option("--seed", seed, "the task resets from this seed (masa_eval's episode 0 of --seed)")->capture_default_str();
  app.add_option("--duration", duration, "seconds of simulated time after the first command")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--state-every", state_every, "publish state every N physics steps")->capture_default_str()->check(CLI::Range(1, 1000));
  app.add_option("--delay-ms", delay_ms, "command delay")->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--jitter-ms", jitter_ms, "extra command delay, uniform in [0, jitter]")->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--loss", loss, "probability that a state or command message is lost")->capture_default_str()->check(CLI::Range(0.0, 1.0));
  app.add_option("--fault-seed", fault_seed, "seed of the delay, jitter and loss generator")->capture_default_str();
  app.add_option("--stop-state-after", stop_state_after, "stop publishing state this many seconds after the first command");
  app.add_option("--nan-state-after", nan_state_after, "publish NaN joint angles from this many seconds after the first command");
  app.add_option("--tilt-state-after", tilt_state_after, "report the base rolled by --tilt-rad from this many seconds after the first command");
  app.add_option("--tilt-rad", tilt_rad, "extra roll reported by --tilt-state-after (rad)")->capture_default_str();
  app.add_option("--url", url, "LCM provider URL (default: LCM_DEFAULT_URL)");
  app.add_option("--state-channel", state_channel)->capture_default_str();
  app.add_option("--command-channel", command_channel)->capture_default_str();
  app.add_flag("--quiet", quiet, "no per-second status line");
  app.add_option("--command-timeout-ms", command_timeout_ms,
                 "no command for this long: the robot damps itself (0: hold the last command for good)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--damping-kd", damping_kd, "kd of the robot's own damping (N m s / rad; the runner's safe.damping_kd)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--command-lead-ms", command_lead_ms,
                 "refuse a command whose utime is ahead of this robot's clock by more than this")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  std::string roster_file;
  auto* roster_opt = app.add_option("--roster", roster_file,
                                    "take only commands signed by a sender this roster permits on the command channel "
                                    "(runner 0)");
  std::string signing_key;
  auto* key_opt = app.add_option("--signing-key", signing_key,
                                 "sign every state message as robot 0 of --roster with this private key (masa_roster "
                                 "make DIR --robot)");
  roster_opt->needs(key_opt);
  key_opt->needs(roster_opt);
  bool insecure = false;
  app.add_flag("--insecure", insecure, "take unsigned commands, send unsigned state: anyone on the network commands the robot")
      ->excludes(roster_opt)->excludes(key_opt);
  std::vector<std::string> perturb;
  std::string perturb_file;
  app.add_option("--perturb", perturb,
                 "a robot that is not the model: KEY=VALUE of env.randomization (e.g. env.randomization.mass_scale=1.2, "
                 "actuator_strength=[0.8,0.9]); ranges drawn from --seed; repeatable");
  app.add_option("--perturb-file", perturb_file, "a YAML file of env.randomization keys (as --perturb)")->check(CLI::ExistingFile);
  CLI11_PARSE(app, argc, argv);
  if (!insecure && roster_file.empty()) {
    std::fprintf(stderr, "masa_sim_robot: the robot channels are signed: give --roster DIR/roster --signing-key "
                         "DIR/keys/robot0.key (masa_roster make DIR --runner --robot), or --insecure\n");
    return 2;
  }
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);

  try {
    policy::LoadedPolicy lp = policy::loadPolicyFile(policy_path);
    bool perturbed = false;
    const YAML::Node env = deploy::perturbedEnv(lp.config.env, perturb, perturb_file, lp.config.origin, &perturbed);
    task::TaskFactory factory(task::taskCatalog(), lp.config.task, lp.spec, env, lp.config.origin, lp.source);
    std::unique_ptr<task::Task> task = factory.create();
    Rng rng(seed);
    task->reset(rng);
    deploy::SimRobot robot(*task, lp.spec);
    std::unique_ptr<deploy::StateNoise> state_noise;
    if (perturbed) {
      const task::PhysicsRandomization& p = *task->randomization();
      const double latency_ms = (p.latencySteps() + p.latencyFraction()) * task->controlTimestep() * 1e3;
      delay_ms += latency_ms;
      Rng noise_rng(seed ^ 0x5eed5eedULL);
      state_noise = std::make_unique<deploy::StateNoise>(p.config(), robot.numJoints(), noise_rng);
      std::fprintf(stderr, "masa_sim_robot: perturbed robot: %s\n", deploy::describePerturbation(*task).c_str());
      std::fprintf(stderr, "masa_sim_robot: perturbed robot: latency %.1f ms (command delay now %.1f ms), state noise std %g, "
                           "bias up to %g\n", latency_ms, delay_ms, p.config().obs_noise_std, p.config().obs_bias);
    }
    const int n = robot.numJoints();
    const deploy::StateFaults state_faults{nan_state_after, tilt_state_after, tilt_rad};
    if (insecure)
      std::fprintf(stderr, "masa_sim_robot: --insecure: commands taken unverified, state unsigned: anyone who can "
                           "publish on %s commands the robot\n", command_channel.c_str());

    transport::Transport lcm(url);
    // Signed, commands arrive through a transport that verifies every message (and cannot publish:
    // the state goes out through `lcm`, signed by state_out).
    std::unique_ptr<transport::Transport> verifying;
    if (!insecure) {
      transport::SignedMode watch;
      watch.roster = std::make_shared<transport::Roster>(transport::Roster::load(roster_file));
      verifying = std::make_unique<transport::Transport>(url, watch);
      std::fprintf(stderr, "masa_sim_robot: commands verified against the roster %s (%zu senders)\n",
                   roster_file.c_str(), watch.roster->entries().size());
    }
    transport::Transport& command_in = verifying ? *verifying : lcm;
    std::shared_ptr<transport::MessageSigner> state_signer;
    if (!insecure) {
      state_signer = transport::loadSignedMode(roster_file, signing_key, {transport::Role::kRobot, 0}).signer;
      std::fprintf(stderr, "masa_sim_robot: state signed as robot 0 with %s\n", signing_key.c_str());
    }
    transport::SignedPublisher state_out(lcm, state_signer);
    deploy::CommandLink link(loss, delay_ms, jitter_ms, fault_seed);
    deploy::RunRecord record(*task);
    deploy::CommandTimeout command_timeout(command_timeout_ms * 1e-3, damping_kd, n);
    deploy::CommandLead command_lead(static_cast<int64_t>(command_lead_ms * 1e3));
    if (command_timeout_ms > 0)
      std::fprintf(stderr, "masa_sim_robot: no command for %.0f ms: the robot damps itself (kp 0, kd %g)\n",
                   command_timeout_ms, damping_kd);
    const auto t_start = Clock::now();
    const auto wall = [&] { return std::chrono::duration<double>(Clock::now() - t_start).count(); };
    masa::lcmt_robot_command incoming{};
    command_in.subscribeRaw(command_channel, [&](const void* data, int size) {
      // Verified (the trailer already gone), or a robot that does not verify: a signing runner's
      // trailer is not part of the command.
      if (!verifying) size = transport::sizeWithoutSigTrailer(data, size);
      if (transport::decodeChecked(data, size, incoming) != transport::WireVerdict::kOk || incoming.num_joints != n) return;
      if (!command_lead.admits(incoming.utime, transport::wallClockMicros())) return;  // counted; changes nothing
      record.commandArrived(incoming);
      const double now = wall();
      if (link.receive(incoming, now)) command_timeout.arrived(incoming, now);
    });

    masa::lcmt_robot_state st{};
    int64_t utime = 0;
    const auto publishState = [&](double sim_t) {
      robot.fillState(st, state_faults, sim_t);
      if (state_noise && state_noise->active()) state_noise->apply(st);
      st.utime = utime = std::max(utime + 1, transport::wallClockMicros());
      if (!link.loseState()) state_out.publish(state_channel, st);
    };

    // Until the first command: state at the physics rate, physics paused.
    const double dt = robot.timestep();
    masa::lcmt_robot_command cmd{};
    bool have_cmd = false;
    while (!g_stop && !have_cmd) {
      publishState(0.0);
      const auto until = Clock::now() + std::chrono::duration<double>(dt * state_every);
      while (Clock::now() < until) command_in.handleTimeout(1);
      have_cmd = link.takeInOrder(wall(), cmd);
    }
    const auto t0 = Clock::now();
    int64_t steps = 0;
    int last_status = 0;
    while (!g_stop && steps * dt < duration) {
      command_in.drain();
      const double now = wall();
      link.takeNewest(now, cmd);  // the newest delivered command wins (jitter may reorder them)
      const masa::lcmt_robot_command& applied = command_timeout.commandFor(cmd, now);
      if (&applied == &cmd) record.applied(cmd.mode, steps * dt); else record.ownSafeState(steps * dt);
      robot.step(applied);
      ++steps;
      const double t = steps * dt;
      const bool stopped = stop_state_after >= 0 && t >= stop_state_after;
      const bool nan = nan_state_after >= 0 && t >= nan_state_after;
      const bool tilted = tilt_state_after >= 0 && t >= tilt_state_after;
      if (stopped || nan || tilted) record.faultFrom(t);
      if (!stopped && steps % state_every == 0) {
        robot.updateKinematics();
        publishState(t);
      }
      if (!quiet && static_cast<int>(t) > last_status) {
        last_status = static_cast<int>(t);
        std::fprintf(stderr, "masa_sim_robot: %d s, command mode %d, %lld commands received\n", last_status, cmd.mode,
                     static_cast<long long>(record.received()));
      }
      std::this_thread::sleep_until(t0 + std::chrono::duration<double>(t));
    }
    robot.updateKinematics();
    const std::vector<double> angles = robot.jointAngles();
    const std::string refused = verifying ? verifying->rejectSummary() : "";
    std::printf("masa_sim_robot: commands refused after decoding: ahead_of_clock %lld (utime more than %.0f ms ahead of "
                "the robot's clock)\n", static_cast<long long>(command_lead.refused()), command_lead_ms);
    record.print(steps * dt, link.lostCommands(), link.lostStates(), verifying ? refused.c_str() : nullptr,
                 tilt_state_after >= 0 ? &angles : nullptr, command_timeout);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_sim_robot: %s\n", e.what());
    return 2;
  }
}
