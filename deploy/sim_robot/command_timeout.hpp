// The robot's own safe state when its runner goes quiet (issue #55, item 2). A robot that applies
// the newest command it has keeps a killed, crashed or cut-off runner's last targets for good; this
// one damps instead. Once no command has arrived for `timeout_s` (wall time, counted from the last
// command that arrived, before the link's delay: arrival is what a robot knows), it applies damping
// of its own: kp 0, kd `damping_kd`, no velocity target, no feed-forward torque, the runner's own
// default safe command (configs/deploy/defaults.yaml, safe.mode damping). The runner that went
// quiet is not followed again (after a silence its targets may be far from where the robot sagged
// to); another runner (a new runner_id, which starts with its ramp from the measured pose) takes
// over. The contract for a real robot's side is in docs/reliability.md, "The robot's side".
#pragma once

#include <cstdint>
#include <vector>

#include "masa/lcmt_robot_command.hpp"

namespace masa::deploy {

class CommandTimeout {
 public:
  // timeout_s <= 0: never (the last command holds for good).
  CommandTimeout(double timeout_s, double damping_kd, int num_joints);

  // A command arrived at wall time now_s. One of a runner that went quiet is counted and changes nothing.
  void arrived(const masa::lcmt_robot_command& cmd, double now_s);
  // What the robot applies at now_s: `newest` (the newest command delivered), or its own damping
  // once the silence passed the bound (tripping it then) or when `newest` is a quiet runner's.
  const masa::lcmt_robot_command& commandFor(const masa::lcmt_robot_command& newest, double now_s);

  double timeoutS() const { return timeout_s_; }
  const masa::lcmt_robot_command& safeCommand() const { return safe_; }
  // The first trip: the silence then (s), and whose commands had stopped; -1 / 0 before any.
  double firstSilenceS() const { return first_silence_s_; }
  int64_t firstQuietRunner() const { return first_quiet_runner_; }
  int64_t ignoredCommands() const { return ignored_; }

 private:
  bool isQuiet(int64_t runner_id) const;

  double timeout_s_;
  masa::lcmt_robot_command safe_;
  bool any_ = false;
  double last_arrival_s_ = 0;
  int64_t last_runner_ = 0;
  std::vector<int64_t> quiet_runners_;
  double first_silence_s_ = -1;
  int64_t first_quiet_runner_ = 0, ignored_ = 0;
};

}  // namespace masa::deploy
