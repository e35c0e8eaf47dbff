#include "deploy/runner/deploy_config.hpp"

#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "common/config/run_config.hpp"
#include "common/core/config_error.hpp"

namespace masa::deploy {

namespace {

YAML::Node loadFile(const std::string& path) {
  if (!std::filesystem::exists(path)) throw ConfigError(path, "(file)", "no such file");
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw ConfigError(path, "(file)", std::string("not valid YAML: ") + e.what());
  }
}

// "a.b=value" as the tree {a: {b: value}}.
YAML::Node overrideTree(const std::string& setting) {
  const auto eq = setting.find('=');
  if (eq == std::string::npos || eq == 0)
    throw ConfigError("command line", setting, "expected key.path=value");
  const std::string path = setting.substr(0, eq);
  YAML::Node value = YAML::Load(setting.substr(eq + 1));
  std::vector<std::string> parts;
  std::stringstream ss(path);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  for (auto it = parts.rbegin(); it != parts.rend(); ++it) {
    YAML::Node parent(YAML::NodeType::Map);
    parent[*it] = value;
    value = parent;
  }
  return value;
}

class Reader {
 public:
  Reader(const YAML::Node& root, const std::map<std::string, std::string>& origin, std::string defaults)
      : root_(root), origin_(origin), defaults_(std::move(defaults)) {}

  template <class T>
  T get(const std::string& path) const {
    YAML::Node n;
    n.reset(root_);
    std::stringstream ss(path);
    for (std::string p; std::getline(ss, p, '.');) n.reset(n[p]);
    try {
      return n.as<T>();
    } catch (const YAML::Exception&) {
      throw ConfigError(originOf(path), path, "not a valid value");
    }
  }
  double number(const std::string& path, double lo, double hi, bool open_lo = false) const {
    const double v = get<double>(path);
    if (!std::isfinite(v) || v < lo || v > hi || (open_lo && v == lo)) {
      std::ostringstream os;
      os << "must be in " << (open_lo ? "(" : "[") << lo << ", " << hi << "], got " << v;
      throw ConfigError(originOf(path), path, os.str());
    }
    return v;
  }
  std::string originOf(const std::string& path) const {
    const auto it = origin_.find(path);
    return it == origin_.end() ? defaults_ : it->second;
  }

 private:
  YAML::Node root_;
  const std::map<std::string, std::string>& origin_;
  std::string defaults_;
};

}  // namespace

std::string defaultDeployConfigPath() { return config::defaultConfigsDir() + "/deploy/defaults.yaml"; }

DeployConfig loadDeployConfig(const std::string& file, const std::vector<std::string>& overrides,
                              const std::string& defaults_path) {
  const YAML::Node schema = loadFile(defaults_path);
  YAML::Node tree = YAML::Clone(schema);
  std::map<std::string, std::string> origin;
  if (!file.empty()) config::overlayChecked(tree, loadFile(file), schema, file, origin);
  for (const std::string& s : overrides) config::overlayChecked(tree, overrideTree(s), schema, "command line", origin);

  const Reader r(tree, origin, defaults_path);
  DeployConfig c;
  c.lcm_url = r.get<std::string>("lcm.url");
  c.state_channel = r.get<std::string>("lcm.state_channel");
  c.command_channel = r.get<std::string>("lcm.command_channel");
  if (c.state_channel.empty() || c.command_channel.empty() || c.state_channel == c.command_channel)
    throw ConfigError(r.originOf("lcm.command_channel"), "lcm.command_channel",
                      "state and command channels must be two different, non-empty names");
  c.control_rate_hz = r.number("control_rate_hz", 0.0, 10000.0);
  c.start_guard_s = r.number("start_guard_s", 0.0, 60.0);
  c.calibration_max_rate = r.number("calibration.max_rate", 0.0, 100.0, true);
  c.calibration_settle_s = r.number("calibration.settle_s", 0.0, 600.0);
  c.stale_after_s = r.number("watchdog.stale_after_s", 0.0, 10.0, true);
  c.action_clip = r.number("limits.action_clip", 0.0, 1e6, true);
  c.position_margin = r.number("limits.position_margin", 0.0, 10.0);
  c.max_target_rate = r.number("limits.max_target_rate", 0.0, 1e6, true);
  c.max_kp = r.number("limits.max_kp", 0.0, 1e6);
  c.max_kd = r.number("limits.max_kd", 0.0, 1e6);
  const std::string mode = r.get<std::string>("safe.mode");
  if (mode == "damping") {
    c.safe_mode = SafeMode::kDamping;
  } else if (mode == "hold") {
    c.safe_mode = SafeMode::kHold;
  } else {
    throw ConfigError(r.originOf("safe.mode"), "safe.mode", "must be damping or hold, got '" + mode + "'");
  }
  c.damping_kd = r.number("safe.damping_kd", 0.0, 1e6);
  c.hold_kp = r.number("safe.hold_kp", 0.0, 1e6);
  c.hold_kd = r.number("safe.hold_kd", 0.0, 1e6);
  c.max_roll = r.number("emergency.max_roll", 0.0, 3.2, true);
  c.max_pitch = r.number("emergency.max_pitch", 0.0, 3.2, true);
  const std::string response = r.get<std::string>("emergency.response");
  if (response == "damping") {
    c.emergency_response = EmergencyResponse::kDamping;
  } else if (response == "crouch") {
    c.emergency_response = EmergencyResponse::kCrouch;
  } else {
    throw ConfigError(r.originOf("emergency.response"), "emergency.response",
                      "must be damping or crouch, got '" + response + "'");
  }
  c.crouch_pose = r.get<std::vector<double>>("emergency.crouch_pose");
  for (double q : c.crouch_pose)
    if (!std::isfinite(q)) throw ConfigError(r.originOf("emergency.crouch_pose"), "emergency.crouch_pose", "not finite");
  if (c.emergency_response == EmergencyResponse::kCrouch && c.crouch_pose.empty())
    throw ConfigError(r.originOf("emergency.response"), "emergency.crouch_pose",
                      "response crouch needs a crouch pose (one angle per joint, action order)");
  c.crouch_max_rate = r.number("emergency.crouch_max_rate", 0.0, 100.0, true);
  // The limits clamp every command's gains: a crouch gain above them would be silently weaker.
  const bool crouch = c.emergency_response == EmergencyResponse::kCrouch;
  c.crouch_kp = r.number("emergency.crouch_kp", 0.0, crouch ? c.max_kp : 1e6);
  c.crouch_kd = r.number("emergency.crouch_kd", 0.0, crouch ? c.max_kd : 1e6);
  const auto integer = [&r](const std::string& path, int lo, int hi) {
    const int v = r.get<int>(path);  // "1.5" is not a valid value
    if (v < lo || v > hi)
      throw ConfigError(r.originOf(path), path, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + std::to_string(v));
    return v;
  };
  c.realtime.cpu = integer("realtime.cpu", -1, 4095);
  c.realtime.priority = integer("realtime.priority", 0, 99);
  c.realtime.lock_memory = r.get<bool>("realtime.lock_memory");
  c.busy_poll_us = integer("realtime.busy_poll_us", 0, 1000000);
  c.warm_up_us = integer("realtime.warm_up_us", 0, 1000000);
  return c;
}

}  // namespace masa::deploy
