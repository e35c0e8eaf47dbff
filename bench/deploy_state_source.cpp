// A robot's state stream for bench/deploy_latency.sh: publishes lcmt_robot_state of the A1 standing
// on its beam (the task's reset pose; utime = the publication time) at --rate-hz and measures, for
// every command that answers one of these states, the round trip from the state's publication to
// the command's arrival, and its two legs split at the command's utime (stamped by the runner just
// before it publishes; one clock, as both run on this machine): state published -> command
// stamped (LCM's delivery and the runner's wakeups, observation, inference) and command stamped ->
// received (the runner's publish, the delivery back and this program's wakeups). Prints p50 / p99
// / max and the command count. With --roster and --signing-key it is the robot of a signed run: it
// signs its states with the robot's key and takes only commands the runner's key signed (the
// default deployment, issue #55). A plain program.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <memory>
#include <cstdio>
#include <thread>
#include <vector>

#include "common/policy/policy_file.hpp"
#include "common/sim/registry.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/transport.hpp"
#include "masa/lcmt_robot_command.hpp"
#include "masa/lcmt_robot_state.hpp"
#include "tasks/tasks.hpp"

using namespace masa;

int main(int argc, char** argv) {
  CLI::App app{"deploy_state_source: A1 states at a fixed rate; command round trips"};
  std::string policy_path = std::string(MASA_SOURCE_DIR) + "/tasks/a1_beam/policy/policy.bin";
  double rate_hz = 500, seconds = 20;
  app.add_option("--policy", policy_path)->capture_default_str();
  app.add_option("--rate-hz", rate_hz)->capture_default_str();
  app.add_option("--seconds", seconds)->capture_default_str();
  std::string roster_file, signing_key;
  app.add_option("--roster", roster_file, "a signed robot: the roster (masa_roster make DIR --runner --robot)");
  app.add_option("--signing-key", signing_key, "the robot's private key file, with --roster");
  CLI11_PARSE(app, argc, argv);
  if (roster_file.empty() != signing_key.empty()) {
    std::fprintf(stderr, "deploy_state_source: --roster and --signing-key go together\n");
    return 2;
  }
  policy::LoadedPolicy lp = policy::loadPolicyFile(policy_path);
  task::TaskFactory factory(task::taskCatalog(), lp.config.task, lp.spec, lp.config.env, lp.config.origin, lp.source);
  auto sim = factory.create();
  Rng rng(0);
  sim->reset(rng);
  const mjModel* m = sim->model();
  const mjData* d = sim->data();
  masa::lcmt_robot_state s{};
  s.num_joints = sim->actDim();
  for (int k = 0; k < sim->actDim(); ++k) {
    const int j = sim->jointOfAction(k);
    s.joint_position.push_back(d->qpos[m->jnt_qposadr[j]]);
    s.joint_velocity.push_back(0.0);
    s.joint_torque.push_back(0.0);
  }
  const int fj = mj_name2id(m, mjOBJ_JOINT, "trunk");
  const double* q = d->qpos + m->jnt_qposadr[fj];
  s.has_base = true;
  s.base_x = q[0], s.base_y = q[1], s.base_z = q[2];
  s.base_qw = q[3], s.base_qx = q[4], s.base_qy = q[5], s.base_qz = q[6];

  auto link = roster_file.empty() ? std::make_unique<transport::Transport>("")
                                  : std::make_unique<transport::Transport>(
                                        "", transport::loadSignedMode(roster_file, signing_key, {transport::Role::kRobot, 0}));
  transport::Transport& lcm = *link;
  std::vector<int64_t> rtt, there, back;
  rtt.reserve(1 << 20);
  there.reserve(1 << 20);
  back.reserve(1 << 20);
  int64_t policy_commands = 0;
  masa::lcmt_robot_command c{};
  lcm.subscribeRaw(transport::kRobotCommandChannel, [&](const void* data, int size) {
    const int64_t now = transport::wallClockMicros();
    if (transport::decodeChecked(data, size, c) != transport::WireVerdict::kOk || c.state_utime <= 0) return;
    if (c.mode == 1) ++policy_commands;
    rtt.push_back(now - c.state_utime);
    there.push_back(c.utime - c.state_utime);
    back.push_back(now - c.utime);
  });
  const auto period = std::chrono::duration<double>(1.0 / rate_hz);
  const auto t0 = std::chrono::steady_clock::now();
  auto next = t0;
  int64_t sent = 0;
  while (std::chrono::steady_clock::now() - t0 < std::chrono::duration<double>(seconds)) {
    s.utime = transport::wallClockMicros();
    lcm.publish(transport::kRobotStateChannel, s);
    ++sent;
    next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
    while (std::chrono::steady_clock::now() < next) lcm.handleTimeout(1);
    lcm.drain();
  }
  for (auto* v : {&rtt, &there, &back}) std::sort(v->begin(), v->end());
  const auto pct = [](const std::vector<int64_t>& v, double p) {
    return static_cast<long long>(v.empty() ? 0 : v[std::min<size_t>(v.size() - 1, p * v.size())]);
  };
  const auto at = [&](double p) { return pct(rtt, p); };
  std::printf("deploy_state_source: %lld states at %.0f Hz; %zu commands answered a state (%lld in policy mode); "
              "round trip state published -> command received: p50 %lld us, p99 %lld us, max %lld us\n",
              static_cast<long long>(sent), rate_hz, rtt.size(), static_cast<long long>(policy_commands),
              static_cast<long long>(at(0.5)), static_cast<long long>(at(0.99)), static_cast<long long>(rtt.empty() ? 0 : rtt.back()));
  std::printf("deploy_state_source: state published -> command stamped by the runner p50 %lld / p99 %lld us; "
              "command stamped -> received here p50 %lld / p99 %lld us\n",
              pct(there, 0.5), pct(there, 0.99), pct(back, 0.5), pct(back, 0.99));
  return 0;
}
