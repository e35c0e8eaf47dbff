// What masa_sim_robot saw of the runner, physics step by physics step, and its closing lines: the
// command modes applied, the task's progress over the policy phase (mode 1) and whether the task's
// termination test fired in it (a fall), when an injected fault began and when the first safe
// command (mode >= 2) came after it, the fastest target change between emergency stops, and when
// the robot damped itself because commands stopped (its command timeout).
#pragma once

#include <cstdint>
#include <vector>

#include "common/sim/task.hpp"
#include "deploy/sim_robot/command_timeout.hpp"
#include "masa/lcmt_robot_command.hpp"

namespace masa::deploy {

class RunRecord {
 public:
  explicit RunRecord(const task::Task& task);

  // A command as it arrived (before any loss or delay): its runner, and emergency-stop rates.
  void commandArrived(const masa::lcmt_robot_command& cmd);
  // The command applied in the physics step that starts at simulated time sim_t.
  void applied(int mode, double sim_t);
  // The robot's own damping (its command timeout) applied in the physics step that starts at sim_t.
  void ownSafeState(double sim_t);
  // An injected fault is in effect from simulated time t (the first call counts).
  void faultFrom(double t);

  int64_t received() const { return received_; }
  // The closing lines (stdout): refused_summary (a verifying robot's rejects by reason) unless null;
  // final_angles (with the emergency-stop rate) unless null.
  void print(double simulated_s, int64_t lost_commands, int64_t lost_states, const char* refused_summary,
             const std::vector<double>* final_angles, const CommandTimeout& timeout) const;

 private:
  const task::Task& task_;
  int64_t received_ = 0;
  std::vector<int64_t> runners_;  // ids of the runners heard
  masa::lcmt_robot_command last_estop_{};
  double estop_max_rate_ = 0;  // rad/s
  int64_t modes_[5] = {0, 0, 0, 0, 0};
  std::vector<double> prog_start_, prog_end_;
  double policy_start_ = -1, policy_end_ = -1, fell_at_ = -1;
  double fault_at_ = -1, safe_after_ = -1, first_safe_at_ = -1;
  int first_safe_mode_ = -1;
  int64_t own_safe_steps_ = 0;
  double own_safe_from_ = -1;
};

}  // namespace masa::deploy
