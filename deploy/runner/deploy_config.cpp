#include "deploy/runner/deploy_config.hpp"

#include "common/config/config_layers.hpp"
#include "common/config/run_config.hpp"
#include "common/core/config_error.hpp"

namespace masa::deploy {

std::string defaultDeployConfigPath() { return config::defaultConfigsDir() + "/deploy/defaults.yaml"; }

DeployConfig loadDeployConfig(const std::string& file, const std::vector<std::string>& overrides,
                              const std::string& defaults_path) {
  config::ConfigLayers layers(config::loadYamlFile(defaults_path), defaults_path);
  if (!file.empty()) layers.overlay(config::loadYamlFile(file), file);
  for (const std::string& s : overrides) {
    const auto [path, value] = config::parseSetting(s);
    layers.set(path, value);
  }
  const config::ConfigSection r = layers.section();
  DeployConfig c;
  c.lcm_url = r.get<std::string>("lcm.url", "an LCM URL");
  c.state_channel = r.get<std::string>("lcm.state_channel", "a channel name");
  c.command_channel = r.get<std::string>("lcm.command_channel", "a channel name");
  if (c.state_channel.empty() || c.command_channel.empty() || c.state_channel == c.command_channel)
    r.fail("lcm.command_channel", "state and command channels must be two different, non-empty names");
  c.control_rate_hz = r.inRange("control_rate_hz", 0.0, 10000.0);
  c.start_guard_s = r.inRange("start_guard_s", 0.0, 60.0);
  c.calibration_max_rate = r.inRange("calibration.max_rate", 0.0, 100.0, true);
  c.calibration_settle_s = r.inRange("calibration.settle_s", 0.0, 600.0);
  c.stale_after_s = r.inRange("watchdog.stale_after_s", 0.0, 10.0, true);
  c.action_clip = r.inRange("limits.action_clip", 0.0, 1e6, true);
  c.position_margin = r.inRange("limits.position_margin", 0.0, 10.0);
  c.max_target_rate = r.inRange("limits.max_target_rate", 0.0, 1e6, true);
  c.max_kp = r.inRange("limits.max_kp", 0.0, 1e6);
  c.max_kd = r.inRange("limits.max_kd", 0.0, 1e6);
  c.safe_mode = r.oneOf("safe.mode", {"damping", "hold"}) == "damping" ? SafeMode::kDamping : SafeMode::kHold;
  c.damping_kd = r.inRange("safe.damping_kd", 0.0, 1e6);
  c.hold_kp = r.inRange("safe.hold_kp", 0.0, 1e6);
  c.hold_kd = r.inRange("safe.hold_kd", 0.0, 1e6);
  c.max_roll = r.inRange("emergency.max_roll", 0.0, 3.2, true);
  c.max_pitch = r.inRange("emergency.max_pitch", 0.0, 3.2, true);
  c.emergency_response = r.oneOf("emergency.response", {"damping", "crouch"}) == "damping"
                             ? EmergencyResponse::kDamping
                             : EmergencyResponse::kCrouch;
  c.crouch_pose = r.get<std::vector<double>>("emergency.crouch_pose", "a list of angles (rad)");
  if (c.emergency_response == EmergencyResponse::kCrouch && c.crouch_pose.empty())
    throw ConfigError(r.originOf("emergency.response"), "emergency.crouch_pose",
                      "response crouch needs a crouch pose (one angle per joint, action order)");
  c.crouch_max_rate = r.inRange("emergency.crouch_max_rate", 0.0, 100.0, true);
  // The limits clamp every command's gains: a crouch gain above them would be silently weaker.
  const bool crouch = c.emergency_response == EmergencyResponse::kCrouch;
  c.crouch_kp = r.inRange("emergency.crouch_kp", 0.0, crouch ? c.max_kp : 1e6);
  c.crouch_kd = r.inRange("emergency.crouch_kd", 0.0, crouch ? c.max_kd : 1e6);
  c.realtime.cpu = r.integerIn("realtime.cpu", -1, 4095);
  c.realtime.priority = r.integerIn("realtime.priority", 0, 99);
  c.realtime.lock_memory = r.get<bool>("realtime.lock_memory", "true or false");
  c.busy_poll_us = r.integerIn("realtime.busy_poll_us", 0, 1000000);
  c.warm_up_us = r.integerIn("realtime.warm_up_us", 0, 1000000);
  return c;
}

}  // namespace masa::deploy
