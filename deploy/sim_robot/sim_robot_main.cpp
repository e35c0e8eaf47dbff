// masa_sim_robot: a task's robot in MuJoCo, stepped in real time, that talks LCM like a robot:
// it publishes lcmt_robot_state and applies the newest lcmt_robot_command with a PD law at every
// physics step (torque = kp (position - q) + kd (velocity - qdot) + torque_ff, clipped to the
// actuator's range), optionally with command delay, jitter and loss of either message (one seeded
// generator). The robot hangs still (physics paused, state published) until the first command.
//   masa_sim_robot tasks/a1_beam/policy/policy.bin --seed 0 --duration 12
// At the end it prints the task's progress figures over the policy phase (commands in mode 1)
// and whether the task's termination test fired (a fall). Fault injection for tests:
// --stop-state-after S stops publishing state, --nan-state-after S publishes NaN joint angles;
// both report when the first safe command (mode >= 2) arrived after the fault; --tilt-state-after S
// reports the base rolled by --tilt-rad more than it is (an IMU's view of a fall), and the robot
// then reports its final joint angles and the fastest target change between emergency-stop commands.
// --roster ROSTER: a robot side that verifies (issue #33, item 2): it takes a command only when it is
// signed by a sender the roster lets publish on the command channel (runner 0, masa_roster make DIR
// --runner; masa_deploy --roster --signing-key) and is new (counter window); others are refused and
// counted by reason, printed at the end. Without it, commands are taken signed or not (unverified).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <deque>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "common/core/build_info.hpp"
#include "common/policy/policy_file.hpp"
#include "common/sim/registry.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/signed_publisher.hpp"
#include "common/transport/transport.hpp"
#include "masa/lcmt_robot_command.hpp"
#include "masa/lcmt_robot_state.hpp"
#include "tasks/tasks.hpp"

using namespace masa;
using Clock = std::chrono::steady_clock;

namespace {

std::atomic<bool> g_stop{false};
void onSignal(int) { g_stop = true; }

struct Pending {
  double deliver_at;  // seconds since start (wall)
  masa::lcmt_robot_command cmd;
};

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
  std::string roster_file;
  app.add_option("--roster", roster_file,
                 "take only commands signed by a sender this roster permits on the command channel (runner 0)");
  CLI11_PARSE(app, argc, argv);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);

  try {
    policy::LoadedPolicy lp = policy::loadPolicyFile(policy_path);
    task::TaskFactory factory(task::taskCatalog(), lp.config.task, lp.spec, lp.config.env, lp.config.origin, lp.source);
    std::unique_ptr<task::Task> task = factory.create();
    Rng rng(seed);
    task->reset(rng);
    const mjModel* m = task->model();
    mjData* d = task->data();
    const int n = task->actDim();
    std::vector<int> qadr(n), vadr(n), act(n);
    for (int k = 0; k < n; ++k) {
      const int j = task->jointOfAction(k);
      if (j < 0) throw std::runtime_error("action " + std::to_string(k) + " drives no joint");
      qadr[k] = m->jnt_qposadr[j];
      vadr[k] = m->jnt_dofadr[j];
      act[k] = task->actuatorOfAction(k);
    }
    int base_q = -1, base_v = -1;
    for (const auto& fj : lp.spec.mujoco().free_joints)
      if (fj.kind == sym::FreeJointKind::kRobotBase) {
        const int j = mj_name2id(m, mjOBJ_JOINT, fj.name.c_str());
        base_q = m->jnt_qposadr[j];
        base_v = m->jnt_dofadr[j];
      }

    transport::Transport lcm(url);
    // With a roster, commands arrive through a transport that verifies every message (and cannot
    // publish: the state goes out unsigned through `lcm`).
    std::unique_ptr<transport::Transport> verifying;
    if (!roster_file.empty()) {
      transport::SignedMode watch;
      watch.roster = std::make_shared<transport::Roster>(transport::Roster::load(roster_file));
      verifying = std::make_unique<transport::Transport>(url, watch);
      std::fprintf(stderr, "masa_sim_robot: commands verified against the roster %s (%zu senders)\n",
                   roster_file.c_str(), watch.roster->entries().size());
    }
    transport::Transport& command_in = verifying ? *verifying : lcm;
    std::mt19937_64 fault(fault_seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const auto t_start = Clock::now();
    const auto wall = [&] { return std::chrono::duration<double>(Clock::now() - t_start).count(); };
    std::deque<Pending> pending;
    int64_t received = 0, lost_commands = 0, lost_states = 0;
    std::vector<int64_t> runners;  // ids of the runners heard
    masa::lcmt_robot_command incoming{}, last_estop{};
    double estop_max_rate = 0;  // rad/s: the fastest target change between two emergency-stop commands
    command_in.subscribeRaw(command_channel, [&](const void* data, int size) {
      // Verified (the trailer already gone), or a robot that does not verify: a signing runner's
      // trailer is not part of the command.
      if (!verifying) size = transport::sizeWithoutSigTrailer(data, size);
      if (transport::decodeChecked(data, size, incoming) != transport::WireVerdict::kOk || incoming.num_joints != n) return;
      ++received;
      if (incoming.mode == 4) {
        if (last_estop.num_joints == n && incoming.utime > last_estop.utime)
          for (int k = 0; k < n; ++k)
            estop_max_rate = std::max(estop_max_rate, std::abs(incoming.position[k] - last_estop.position[k]) /
                                                          ((incoming.utime - last_estop.utime) * 1e-6));
        last_estop = incoming;
      }
      if (std::find(runners.begin(), runners.end(), incoming.runner_id) == runners.end()) runners.push_back(incoming.runner_id);
      if (loss > 0 && unit(fault) < loss) {
        ++lost_commands;
        return;
      }
      pending.push_back({wall() + 1e-3 * (delay_ms + jitter_ms * unit(fault)), incoming});
    });

    masa::lcmt_robot_command cmd{};
    bool have_cmd = false;
    masa::lcmt_robot_state st{};
    st.num_joints = n;
    st.joint_position.assign(n, 0.0);
    st.joint_velocity.assign(n, 0.0);
    st.joint_torque.assign(n, 0.0);
    st.has_base = base_q >= 0;
    int64_t utime = 0;
    const auto publishState = [&](double sim_t) {
      const bool nan = nan_state_after >= 0 && sim_t >= nan_state_after;
      for (int k = 0; k < n; ++k) {
        st.joint_position[k] = nan ? std::numeric_limits<double>::quiet_NaN() : d->qpos[qadr[k]];
        st.joint_velocity[k] = d->qvel[vadr[k]];
        st.joint_torque[k] = d->actuator_force[act[k]] * m->actuator_gear[6 * act[k]];
      }
      if (base_q >= 0) {
        const double* q = d->qpos + base_q;
        const double* v = d->qvel + base_v;
        st.base_x = q[0], st.base_y = q[1], st.base_z = q[2];
        st.base_qw = q[3], st.base_qx = q[4], st.base_qy = q[5], st.base_qz = q[6];
        if (tilt_state_after >= 0 && sim_t >= tilt_state_after) {  // q * (rotation about the body x by tilt_rad)
          const double tilt[4] = {std::cos(tilt_rad / 2), std::sin(tilt_rad / 2), 0, 0};
          double out[4];
          mju_mulQuat(out, q + 3, tilt);
          st.base_qw = out[0], st.base_qx = out[1], st.base_qy = out[2], st.base_qz = out[3];
        }
        st.base_vx = v[0], st.base_vy = v[1], st.base_vz = v[2];
        st.base_wx = v[3], st.base_wy = v[4], st.base_wz = v[5];
      }
      st.utime = utime = std::max(utime + 1, transport::wallClockMicros());
      if (loss > 0 && unit(fault) < loss) {
        ++lost_states;
        return;
      }
      lcm.publish(state_channel, st);
    };

    // Until the first command: state at the physics rate, physics paused.
    const double dt = m->opt.timestep;
    const int nprog = static_cast<int>(task->progressNames().size());
    std::vector<double> prog_start(nprog, 0.0), prog_end(nprog, 0.0);
    double policy_start = -1, policy_end = -1, fell_at = -1, fault_at = -1, safe_after = -1, first_safe_at = -1;
    int first_safe_mode = -1;
    int64_t steps = 0, modes[5] = {0, 0, 0, 0, 0};
    while (!g_stop && !have_cmd) {
      publishState(0.0);
      const auto until = Clock::now() + std::chrono::duration<double>(dt * state_every);
      while (Clock::now() < until) command_in.handleTimeout(1);
      while (!pending.empty() && pending.front().deliver_at <= wall()) {
        cmd = pending.front().cmd;
        pending.pop_front();
        have_cmd = true;
      }
    }
    const auto t0 = Clock::now();
    int last_status = 0;
    while (!g_stop && steps * dt < duration) {
      const double sim_t = steps * dt;
      command_in.drain();
      const double now = wall();
      // The newest delivered command wins (jitter may deliver out of order).
      for (auto it = pending.begin(); it != pending.end();) {
        if (it->deliver_at <= now) {
          if (it->cmd.utime >= cmd.utime) cmd = it->cmd;
          it = pending.erase(it);
        } else {
          ++it;
        }
      }
      const int mode = cmd.mode;
      if (mode >= 0 && mode < 5) ++modes[mode];
      if (mode == 1 && policy_start < 0) {
        policy_start = sim_t;
        task->progress(prog_start.data());
      }
      if (mode == 1) {
        policy_end = sim_t;
        task->progress(prog_end.data());
        if (fell_at < 0 && task->terminatedNow()) fell_at = sim_t;
      }
      if (mode >= 2 && first_safe_mode < 0) {
        first_safe_mode = mode;
        first_safe_at = sim_t;
      }
      if (fault_at >= 0 && safe_after < 0 && mode >= 2) safe_after = sim_t - fault_at;
      for (int k = 0; k < n; ++k) {
        const int a = act[k];
        const double tau = cmd.kp[k] * (cmd.position[k] - d->qpos[qadr[k]]) + cmd.kd[k] * (cmd.velocity[k] - d->qvel[vadr[k]]) +
                           cmd.torque_ff[k];
        double u = tau / m->actuator_gear[6 * a];
        if (m->actuator_ctrllimited[a]) u = std::clamp(u, m->actuator_ctrlrange[2 * a], m->actuator_ctrlrange[2 * a + 1]);
        d->ctrl[a] = std::isfinite(u) ? u : 0.0;
      }
      mj_step(m, d);
      ++steps;
      const double t = steps * dt;
      const bool stopped = stop_state_after >= 0 && t >= stop_state_after;
      const bool nan = nan_state_after >= 0 && t >= nan_state_after;
      const bool tilted = tilt_state_after >= 0 && t >= tilt_state_after;
      if ((stopped || nan || tilted) && fault_at < 0) fault_at = t;
      if (!stopped && steps % state_every == 0) {
        mj_kinematics(m, d);
        publishState(t);
      }
      if (!quiet && static_cast<int>(t) > last_status) {
        last_status = static_cast<int>(t);
        std::fprintf(stderr, "masa_sim_robot: %d s, command mode %d, %lld commands received\n", last_status, mode,
                     static_cast<long long>(received));
      }
      std::this_thread::sleep_until(t0 + std::chrono::duration<double>(t));
    }
    mj_kinematics(m, d);
    std::printf("masa_sim_robot: commands from %zu runner(s)\n", runners.size());
    if (verifying)
      std::printf("masa_sim_robot: commands refused before decoding: %s\n", verifying->rejectSummary().c_str());
    std::printf("masa_sim_robot: %.2f s simulated, %lld commands received (%lld lost), %lld states lost; command modes:"
                " calibrating %lld, policy %lld, damping %lld, hold %lld, estop %lld physics steps\n",
                steps * dt, static_cast<long long>(received), static_cast<long long>(lost_commands),
                static_cast<long long>(lost_states), static_cast<long long>(modes[0]), static_cast<long long>(modes[1]),
                static_cast<long long>(modes[2]), static_cast<long long>(modes[3]), static_cast<long long>(modes[4]));
    if (policy_start >= 0) {
      std::printf("masa_sim_robot: policy phase %.2f s (%lld control periods of %.3f s)", policy_end - policy_start,
                  std::llround((policy_end - policy_start) / task->controlTimestep()), task->controlTimestep());
      for (int i = 0; i < nprog; ++i)
        std::printf(", %s %.3f -> %.3f (change %.3f)", task->progressNames()[i].c_str(), prog_start[i], prog_end[i],
                    prog_end[i] - prog_start[i]);
      std::printf("; fell: %s\n", fell_at >= 0 ? "yes" : "no");
      if (fell_at >= 0) std::printf("masa_sim_robot: fell at %.2f s\n", fell_at);
    }
    if (tilt_state_after >= 0) {
      std::printf("masa_sim_robot: final joint angles:");
      for (int k = 0; k < n; ++k) std::printf(" %.3f", d->qpos[qadr[k]]);
      std::printf("\nmasa_sim_robot: fastest target change between emergency-stop commands: %.3f rad/s\n", estop_max_rate);
    }
    // A safe command before the fault answers something else (a runner that missed its state on a
    // loaded machine), not the fault: said apart, so that a test does not time it from the fault.
    if (fault_at >= 0 && first_safe_at >= 0 && first_safe_at < fault_at)
      std::printf("masa_sim_robot: fault at %.3f s; first safe command (mode %d) came before it, at %.3f s\n", fault_at,
                  first_safe_mode, first_safe_at);
    else if (fault_at >= 0)
      std::printf("masa_sim_robot: fault at %.3f s; first safe command (mode %d) %s\n", fault_at, first_safe_mode,
                  safe_after >= 0 ? ("applied " + std::to_string(safe_after) + " s after it").c_str() : "never arrived");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_sim_robot: %s\n", e.what());
    return 2;
  }
}
