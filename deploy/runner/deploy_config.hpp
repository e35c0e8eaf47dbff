// masa_deploy's configuration (configs/deploy/defaults.yaml is the defaults and the schema): LCM
// channels, control rate, start guard, calibration ramp, watchdog, limits, safe command and
// emergency stop. Errors name the file (or "command line") and the key.
#pragma once

#include <string>
#include <vector>

#include "deploy/runner/realtime.hpp"

namespace masa::deploy {

enum class SafeMode { kDamping, kHold };
// What the emergency stop (orientation limit) commands.
enum class EmergencyResponse { kDamping, kCrouch };

struct DeployConfig {
  std::string lcm_url;
  std::string state_channel = "MASA_ROBOT_STATE";
  std::string command_channel = "MASA_ROBOT_COMMAND";
  double control_rate_hz = 0.0;  // 0: the task's
  double start_guard_s = 0.5;
  double calibration_max_rate = 0.5;  // rad/s
  double calibration_settle_s = 1.0;
  double stale_after_s = 0.05;
  double action_clip = 1.0;
  double position_margin = 0.05;   // rad
  double max_target_rate = 30.0;   // rad/s
  double max_kp = 100.0, max_kd = 5.0;
  SafeMode safe_mode = SafeMode::kDamping;
  double damping_kd = 2.0;
  double hold_kp = 40.0, hold_kd = 1.0;
  double max_roll = 0.8, max_pitch = 0.8;  // rad
  EmergencyResponse emergency_response = EmergencyResponse::kDamping;
  std::vector<double> crouch_pose;  // rad per joint, action order (its size is checked against the robot)
  double crouch_max_rate = 1.0;     // rad/s
  double crouch_kp = 40.0, crouch_kd = 1.0;
  RealtimeSettings realtime;
  int busy_poll_us = 0;  // spin this long before a command is due (0: sleep until a state arrives)
  int warm_up_us = 0;    // PolicyRunner::warmUp() this long before a command is due (0: never)
};

// configs/deploy/defaults.yaml of this source tree (or $MASA_CONFIGS/deploy/defaults.yaml).
std::string defaultDeployConfigPath();

// Defaults, then `file` (when not empty), then "key.path=value" overrides; checked against the
// defaults' keys and value ranges. Throws ConfigError naming the file and key.
DeployConfig loadDeployConfig(const std::string& file, const std::vector<std::string>& overrides = {},
                              const std::string& defaults_path = defaultDeployConfigPath());

}  // namespace masa::deploy
