#include "deploy/sim_robot/run_record.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace masa::deploy {

RunRecord::RunRecord(const task::Task& task)
    : task_(task), prog_start_(task.progressNames().size(), 0.0), prog_end_(task.progressNames().size(), 0.0) {}

void RunRecord::commandArrived(const masa::lcmt_robot_command& cmd) {
  ++received_;
  if (cmd.mode == 4) {
    if (last_estop_.num_joints == cmd.num_joints && cmd.utime > last_estop_.utime)
      for (int k = 0; k < cmd.num_joints; ++k)
        estop_max_rate_ = std::max(estop_max_rate_, std::abs(cmd.position[k] - last_estop_.position[k]) /
                                                        ((cmd.utime - last_estop_.utime) * 1e-6));
    last_estop_ = cmd;
  }
  if (std::find(runners_.begin(), runners_.end(), cmd.runner_id) == runners_.end()) runners_.push_back(cmd.runner_id);
}

void RunRecord::applied(int mode, double sim_t) {
  if (mode >= 0 && mode < 5) ++modes_[mode];
  if (mode == 1 && policy_start_ < 0) {
    policy_start_ = sim_t;
    task_.progress(prog_start_.data());
  }
  if (mode == 1) {
    policy_end_ = sim_t;
    task_.progress(prog_end_.data());
    if (fell_at_ < 0 && task_.terminatedNow()) fell_at_ = sim_t;
  }
  if (mode >= 2 && first_safe_mode_ < 0) {
    first_safe_mode_ = mode;
    first_safe_at_ = sim_t;
  }
  if (fault_at_ >= 0 && safe_after_ < 0 && mode >= 2) safe_after_ = sim_t - fault_at_;
}

void RunRecord::ownSafeState(double sim_t) {
  if (own_safe_from_ < 0) own_safe_from_ = sim_t;
  ++own_safe_steps_;
}

void RunRecord::faultFrom(double t) {
  if (fault_at_ < 0) fault_at_ = t;
}

void RunRecord::print(double simulated_s, int64_t lost_commands, int64_t lost_states, const char* refused_summary,
                      const std::vector<double>* final_angles, const CommandTimeout& timeout) const {
  std::printf("masa_sim_robot: commands from %zu runner(s)\n", runners_.size());
  if (refused_summary) std::printf("masa_sim_robot: commands refused before decoding: %s\n", refused_summary);
  std::printf("masa_sim_robot: %.2f s simulated, %lld commands received (%lld lost), %lld states lost; command modes:"
              " calibrating %lld, policy %lld, damping %lld, hold %lld, estop %lld physics steps\n",
              simulated_s, static_cast<long long>(received_), static_cast<long long>(lost_commands),
              static_cast<long long>(lost_states), static_cast<long long>(modes_[0]), static_cast<long long>(modes_[1]),
              static_cast<long long>(modes_[2]), static_cast<long long>(modes_[3]), static_cast<long long>(modes_[4]));
  if (policy_start_ >= 0) {
    std::printf("masa_sim_robot: policy phase %.2f s (%lld control periods of %.3f s)", policy_end_ - policy_start_,
                std::llround((policy_end_ - policy_start_) / task_.controlTimestep()), task_.controlTimestep());
    const auto& names = task_.progressNames();
    for (std::size_t i = 0; i < names.size(); ++i)
      std::printf(", %s %.3f -> %.3f (change %.3f)", names[i].c_str(), prog_start_[i], prog_end_[i],
                  prog_end_[i] - prog_start_[i]);
    std::printf("; fell: %s\n", fell_at_ >= 0 ? "yes" : "no");
    if (fell_at_ >= 0) std::printf("masa_sim_robot: fell at %.2f s\n", fell_at_);
  }
  if (final_angles) {
    std::printf("masa_sim_robot: final joint angles:");
    for (double q : *final_angles) std::printf(" %.3f", q);
    std::printf("\nmasa_sim_robot: fastest target change between emergency-stop commands: %.3f rad/s\n", estop_max_rate_);
  }
  if (timeout.firstSilenceS() >= 0)
    std::printf("masa_sim_robot: command timeout: no command for %.3f s (bound %.3f s) from runner %lld: the robot's own "
                "damping for %lld physics steps from %.3f s simulated (kp 0, kd %g); that runner was not followed again "
                "(%lld of its commands ignored)\n",
                timeout.firstSilenceS(), timeout.timeoutS(), static_cast<long long>(timeout.firstQuietRunner()),
                static_cast<long long>(own_safe_steps_), own_safe_from_, timeout.safeCommand().kd.empty() ? 0.0 : timeout.safeCommand().kd[0],
                static_cast<long long>(timeout.ignoredCommands()));
  // A safe command before the fault answers something else (a runner that missed its state on a
  // loaded machine), not the fault: said apart, so that a test does not time it from the fault.
  if (fault_at_ >= 0 && first_safe_at_ >= 0 && first_safe_at_ < fault_at_)
    std::printf("masa_sim_robot: fault at %.3f s; first safe command (mode %d) came before it, at %.3f s\n", fault_at_,
                first_safe_mode_, first_safe_at_);
  else if (fault_at_ >= 0)
    std::printf("masa_sim_robot: fault at %.3f s; first safe command (mode %d) %s\n", fault_at_, first_safe_mode_,
                safe_after_ >= 0 ? ("applied " + std::to_string(safe_after_) + " s after it").c_str() : "never arrived");
}

}  // namespace masa::deploy
