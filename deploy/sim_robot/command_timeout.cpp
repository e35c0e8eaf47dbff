#include "deploy/sim_robot/command_timeout.hpp"

#include <algorithm>

namespace masa::deploy {

CommandTimeout::CommandTimeout(double timeout_s, double damping_kd, int num_joints) : timeout_s_(timeout_s) {
  safe_.num_joints = num_joints;
  safe_.position.assign(num_joints, 0.0);
  safe_.velocity.assign(num_joints, 0.0);
  safe_.torque_ff.assign(num_joints, 0.0);
  safe_.kp.assign(num_joints, 0.0);
  safe_.kd.assign(num_joints, damping_kd);
  safe_.mode = 2;  // damping, as the runner numbers its modes
}

bool CommandTimeout::isQuiet(int64_t runner_id) const {
  return std::find(quiet_runners_.begin(), quiet_runners_.end(), runner_id) != quiet_runners_.end();
}

void CommandTimeout::arrived(const masa::lcmt_robot_command& cmd, double now_s) {
  if (isQuiet(cmd.runner_id)) {
    ++ignored_;
    return;
  }
  any_ = true;
  last_arrival_s_ = now_s;
  last_runner_ = cmd.runner_id;
}

const masa::lcmt_robot_command& CommandTimeout::commandFor(const masa::lcmt_robot_command& newest, double now_s) {
  if (timeout_s_ <= 0) return newest;
  if (any_ && !isQuiet(last_runner_) && now_s - last_arrival_s_ > timeout_s_) {
    quiet_runners_.push_back(last_runner_);
    if (first_silence_s_ < 0) {
      first_silence_s_ = now_s - last_arrival_s_;
      first_quiet_runner_ = last_runner_;
    }
  }
  return isQuiet(newest.runner_id) ? safe_ : newest;
}

}  // namespace masa::deploy
