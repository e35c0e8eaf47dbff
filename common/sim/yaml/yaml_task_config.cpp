#include "common/sim/yaml/yaml_task_config.hpp"

#include <cmath>
#include <map>

#include "common/sim/yaml/yaml_fields.hpp"

namespace masa::task {
namespace {

const std::map<std::string, ObsSource> kSources = {
    {"joint_pos", ObsSource::kJointPos},       {"joint_vel", ObsSource::kJointVel},
    {"last_action", ObsSource::kLastAction},   {"body_pos", ObsSource::kBodyPos},
    {"body_lin_vel", ObsSource::kBodyLinVel},  {"body_ang_vel", ObsSource::kBodyAngVel},
    {"body_quat_w", ObsSource::kBodyQuatW},    {"body_quat_xyz", ObsSource::kBodyQuatXyz},
    {"body_axis", ObsSource::kBodyAxis},       {"body_euler", ObsSource::kBodyEuler},
    {"heading", ObsSource::kHeading},          {"sensor", ObsSource::kSensor},
};

const std::map<std::string, RewardType> kRewards = {
    {"alive", RewardType::kAlive},
    {"forward_velocity", RewardType::kForwardVelocity},
    {"heading", RewardType::kHeading},
    {"upright", RewardType::kUpright},
    {"lateral_velocity", RewardType::kLateralVelocity},
    {"action_squared", RewardType::kActionSquared},
    {"energy", RewardType::kEnergy},
};

const std::map<std::string, TerminationType> kTerminations = {
    {"height", TerminationType::kHeight},
    {"upright", TerminationType::kUpright},
};

template <class T>
std::string keysOf(const std::map<std::string, T>& m) {
  std::string s;
  for (const auto& [k, v] : m) s += (s.empty() ? "" : ", ") + k;
  return s;
}

// The value of a `type:`/`source:` key, looked up in `table`, before the mapping's other keys are
// known (they depend on it).
template <class T>
T lookupType(const YAML::Node& n, const std::string& key, const std::map<std::string, T>& table,
             const std::string& path, const std::string& file) {
  if (!n.IsMap()) failAt(file, path, n, "expected a mapping with a '" + key + "' key");
  const YAML::Node v = n[key];
  if (!v.IsDefined() || !v.IsScalar()) failAt(file, path, n, "missing '" + key + "' (one of " + keysOf(table) + ")");
  const auto it = table.find(v.Scalar());
  if (it == table.end())
    failAt(file, path + "." + key, v, "unknown " + key + " '" + v.Scalar() + "' (one of " + keysOf(table) + ")");
  return it->second;
}

bool flag(const YamlFields& f, const std::string& key, bool fallback) {
  if (!f.has(key)) return fallback;
  try {
    return f.node(key).as<bool>();
  } catch (const YAML::Exception&) {
    f.fail(key, "expected true or false");
  }
}

int axisIndex(const YamlFields& f, const std::string& key, int fallback) {
  if (!f.has(key)) return fallback;
  const std::string a = f.text(key);
  if (a == "x") return 0;
  if (a == "y") return 1;
  if (a == "z") return 2;
  f.fail(key, "expected x, y or z, got '" + a + "'");
}

std::vector<int> componentList(const YamlFields& f) {
  if (!f.has("components")) return {0, 1, 2};
  const std::string c = f.text("components");
  std::vector<int> out;
  for (char ch : c) {
    if (ch < 'x' || ch > 'z') f.fail("components", "expected letters among x, y, z in order, got '" + c + "'");
    if (!out.empty() && ch - 'x' <= out.back()) f.fail("components", "list each of x, y, z once, in order: '" + c + "'");
    out.push_back(ch - 'x');
  }
  return out;
}

// A name, or one per limb: a list of num_limbs names, or one name with "{limb}" in it.
std::vector<std::string> namesPerLimb(const YamlFields& f, const std::string& key, bool limb, int num_limbs) {
  const YAML::Node n = f.node(key);
  if (limb && n.IsSequence()) {
    if (static_cast<int>(n.size()) != num_limbs)
      f.fail(key, "has " + std::to_string(n.size()) + " names; the group has " + std::to_string(num_limbs) + " limbs");
    std::vector<std::string> names;
    for (const auto& e : n) names.push_back(e.as<std::string>());
    return names;
  }
  const std::string name = f.text(key);
  const auto at = name.find("{limb}");
  if (!limb) {
    if (at != std::string::npos) f.fail(key, "'{limb}' belongs in limb entries; a central entry names one thing");
    return {name};
  }
  const bool is_action_slot = key == "action";  // a limb's action slot names the same slot in every limb
  if (at == std::string::npos && !is_action_slot)
    f.fail(key, "a limb entry names one " + key + " per limb: a list of " + std::to_string(num_limbs) +
                    " names, or a name with '{limb}' (replaced by 0 .. " + std::to_string(num_limbs - 1) + ")");
  std::vector<std::string> names;
  for (int k = 0; k < num_limbs; ++k) {
    std::string s = name;
    if (at != std::string::npos) s.replace(at, 6, std::to_string(k));
    names.push_back(s);
  }
  return names;
}

ObservationSourceConfig readSource(const YAML::Node& n, const std::string& entry, const std::string& path,
                                   const std::string& file, bool limb, int num_limbs) {
  ObservationSourceConfig c;
  c.entry = entry;
  c.path = path;
  c.file = file;
  c.source = lookupType(n, "source", kSources, path, file);
  std::vector<std::string> keys = {"source"};
  switch (c.source) {
    case ObsSource::kJointPos: keys.insert(keys.end(), {"action", "joint", "from_pose"}); break;
    case ObsSource::kJointVel:
    case ObsSource::kLastAction: keys.insert(keys.end(), {"action", "joint"}); break;
    case ObsSource::kBodyPos: keys.insert(keys.end(), {"body", "components", "above_geom"}); break;
    case ObsSource::kBodyLinVel: keys.insert(keys.end(), {"body", "components"}); break;
    case ObsSource::kBodyAngVel: keys.insert(keys.end(), {"body", "components", "frame"}); break;
    case ObsSource::kBodyQuatW:
    case ObsSource::kBodyQuatXyz: keys.push_back("body"); break;
    case ObsSource::kBodyAxis: keys.insert(keys.end(), {"body", "axis"}); break;
    case ObsSource::kBodyEuler: keys.insert(keys.end(), {"body", "angle"}); break;
    case ObsSource::kHeading: keys.push_back("components"); break;
    case ObsSource::kSensor: keys.push_back("sensor"); break;
  }
  const YamlFields f(n, path, file, keys);
  if (f.has("action") && f.has("joint")) f.fail("joint", "give either action or joint, not both");
  for (const char* key : {"action", "joint", "body", "sensor"})
    if (f.has(key)) {
      c.name_key = key;
      c.names = namesPerLimb(f, key, limb, num_limbs);
    }
  if (c.name_key.empty() && c.source != ObsSource::kHeading)
    f.fail("", "missing the name of what it observes (key " + keys[1] + ")");
  c.components = componentList(f);
  c.axis = axisIndex(f, "axis", 2);
  if (f.has("angle")) {
    const std::string a = f.text("angle");
    c.axis = a == "roll" ? 0 : a == "pitch" ? 1 : a == "yaw" ? 2 : -1;
    if (c.axis < 0) f.fail("angle", "expected roll, pitch or yaw, got '" + a + "'");
  } else if (c.source == ObsSource::kBodyEuler) {
    f.fail("", "missing 'angle' (roll, pitch or yaw)");
  }
  const std::string frame = f.text("frame", "world");
  if (frame != "world" && frame != "body") f.fail("frame", "expected world or body, got '" + frame + "'");
  c.body_frame = frame == "body";
  c.from_pose = flag(f, "from_pose", false);
  c.above_geom = f.text("above_geom", "");
  if (!c.above_geom.empty() && c.components != std::vector<int>{2})
    f.fail("above_geom", "a height above a geom is the z component alone: add components: z");
  return c;
}

std::vector<ObservationSourceConfig> readBlock(EnvParams& p, const YAML::Node& block, const std::string& key,
                                               bool limb, int num_limbs) {
  std::vector<ObservationSourceConfig> out;
  if (!block.IsDefined() || block.IsNull()) return out;
  const std::string path = "env.observation." + key;
  if (!block.IsMap()) failAt(p.origin("observation." + key), path, block, "expected a mapping: spec entry name -> source");
  for (const auto& kv : block) {
    const std::string entry = kv.first.Scalar();
    out.push_back(readSource(kv.second, entry, path + "." + entry, p.origin("observation." + key + "." + entry), limb,
                             num_limbs));
  }
  return out;
}

// Calls read(name, node, key path, file) for each entry of the mapping env.<section> (name -> {type, ...}).
template <class Read>
void forEachNamed(EnvParams& p, const std::string& section, Read read) {
  const YAML::Node n = p.section(section);
  if (!n.IsDefined() || n.IsNull()) return;
  if (!n.IsMap()) failAt(p.origin(section), "env." + section, n, "expected a mapping: name -> {type, ...}");
  for (const auto& kv : n) {
    const std::string name = kv.first.Scalar();
    read(name, kv.second, "env." + section + "." + name, p.origin(section + "." + name));
  }
}

std::vector<RewardTermConfig> readReward(EnvParams& p) {
  std::vector<RewardTermConfig> out;
  forEachNamed(p, "reward", [&](const std::string& name, const YAML::Node& n, const std::string& path,
                                const std::string& file) {
    RewardTermConfig t;
    t.name = name;
    t.path = path;
    t.file = file;
    if (name == "termination") failAt(file, path, n, "'termination' is the name of the termination reward");
    t.type = lookupType(n, "type", kRewards, path, file);
    std::vector<std::string> keys = {"type"};
    switch (t.type) {
      case RewardType::kForwardVelocity: keys.insert(keys.end(), {"body", "target"}); break;
      case RewardType::kHeading: keys.insert(keys.end(), {"body", "axis"}); break;
      case RewardType::kUpright: keys.insert(keys.end(), {"body", "axis", "min"}); break;
      case RewardType::kLateralVelocity: keys.push_back("body"); break;
      default: break;
    }
    const YamlFields f(n, path, file, keys);
    if (keys.size() > 1) t.body = f.text("body");
    t.axis = axisIndex(f, "axis", t.type == RewardType::kUpright ? 2 : 0);
    t.has_target = f.has("target");
    t.target = f.number("target", 0.0);
    t.has_threshold = f.has("min");
    t.threshold = f.number("min", 0.0);
    out.push_back(t);
  });
  return out;
}

std::vector<TerminationConfig> readTermination(EnvParams& p) {
  std::vector<TerminationConfig> out;
  forEachNamed(p, "termination", [&](const std::string& name, const YAML::Node& n, const std::string& path,
                                     const std::string& file) {
    TerminationConfig t;
    t.name = name;
    t.path = path;
    t.file = file;
    t.type = lookupType(n, "type", kTerminations, path, file);
    const YamlFields f(n, path, file,
                       t.type == TerminationType::kHeight
                           ? std::vector<std::string>{"type", "body", "above", "above_geom", "min"}
                           : std::vector<std::string>{"type", "body", "axis", "min"});
    t.body = f.text("body");
    t.above = f.text("above", "");
    t.above_geom = f.text("above_geom", "");
    if (!t.above.empty() && !t.above_geom.empty()) f.fail("above_geom", "give either above (a body) or above_geom");
    t.axis = axisIndex(f, "axis", 2);
    t.min = f.number("min");
    out.push_back(t);
  });
  return out;
}

std::vector<PoseJointConfig> readPose(EnvParams& p) {
  std::vector<PoseJointConfig> out;
  const YAML::Node n = p.section("pose");
  if (!n.IsDefined() || n.IsNull()) return out;
  const std::string file = p.origin("pose");
  if (!n.IsMap()) failAt(file, "env.pose", n, "expected a mapping: action entry or joint name -> position");
  for (const auto& kv : n) {
    PoseJointConfig j{kv.first.Scalar(), "env.pose." + kv.first.Scalar(), file, 0.0};
    try {
      j.value = kv.second.as<double>();
    } catch (const YAML::Exception&) {
      failAt(file, j.path, kv.second, "expected a number (rad, or m for a slide joint)");
    }
    if (!std::isfinite(j.value)) failAt(file, j.path, kv.second, "expected a finite number (rad, or m for a slide joint)");
    out.push_back(j);
  }
  return out;
}

ActuationConfig readActuation(EnvParams& p) {
  ActuationConfig a;
  const YAML::Node n = p.section("actuation");
  a.file = p.origin("actuation");
  if (!n.IsDefined() || n.IsNull()) return a;
  const std::string type = n.IsMap() && n["type"] ? n["type"].as<std::string>() : "";
  const bool pd = type == "pd";
  const YamlFields f(n, "env.actuation", p.origin("actuation"),
                     pd ? std::vector<std::string>{"type", "kp", "kd", "action_scale"} : std::vector<std::string>{"type"});
  if (type != "pd" && type != "ctrlrange") f.fail("type", "expected ctrlrange (the default) or pd, got '" + type + "'");
  a.pd = pd;
  if (!pd) return a;
  a.kp = f.number("kp");
  a.kd = f.number("kd");
  a.action_scale = f.number("action_scale");
  if (!(a.kp > 0)) f.fail("kp", "must be positive");
  if (a.kd < 0) f.fail("kd", "must be >= 0");
  if (!(a.action_scale > 0)) f.fail("action_scale", "must be positive");
  return a;
}

ResetConfig readReset(EnvParams& p) {
  ResetConfig r;
  const YAML::Node n = p.section("reset");
  r.path = "env.reset";
  r.file = p.origin("reset");
  if (!n.IsDefined() || n.IsNull()) return r;
  const YamlFields f(n, r.path, r.file, {"joint_noise", "joint_velocity_noise", "velocity_noise", "rest_on"});
  for (const char* key : {"joint_noise", "joint_velocity_noise", "velocity_noise"})
    if (f.number(key, 0.0) < 0) f.fail(key, "must be >= 0");
  r.joint_noise = f.number("joint_noise", 0.0);
  r.joint_velocity_noise = f.number("joint_velocity_noise", 0.0);
  r.velocity_noise = f.number("velocity_noise", 0.0);
  if (f.has("rest_on")) {
    const YamlFields rest(f.node("rest_on"), f.pathOf("rest_on"), r.file, {"support", "feet", "clearance"});
    r.support = rest.text("support");
    const YAML::Node feet = rest.node("feet");
    if (!feet.IsSequence() || feet.size() == 0) rest.fail("feet", "expected a list of geom names");
    for (const auto& g : feet) r.feet.push_back(g.as<std::string>());
    r.clearance = rest.number("clearance", 0.0);
  }
  return r;
}

HeadingConfig readHeading(EnvParams& p) {
  HeadingConfig h;
  const YAML::Node n = p.section("heading");
  if (!n.IsDefined() || n.IsNull()) return h;
  const YamlFields f(n, "env.heading", p.origin("heading"), {"direction", "random_yaw"});
  if (f.has("direction")) {
    const YAML::Node d = f.node("direction");
    if (!d.IsSequence() || (d.size() != 2 && d.size() != 3)) f.fail("direction", "expected [x, y] or [x, y, 0]");
    try {
      h.direction = Eigen::Vector3d(d[0].as<double>(), d[1].as<double>(), d.size() == 3 ? d[2].as<double>() : 0.0);
    } catch (const YAML::Exception&) {
      f.fail("direction", "expected numbers");
    }
    if (!h.direction.allFinite()) f.fail("direction", "expected finite numbers");
    if (h.direction.z() != 0.0 || h.direction.norm() < 1e-9)
      f.fail("direction", "must be a horizontal, non-zero vector (z = 0)");
    h.direction.normalize();
  }
  if (f.has("random_yaw")) {
    try {
      h.random_yaw = f.node("random_yaw").as<bool>();
    } catch (const YAML::Exception&) {
      f.fail("random_yaw", "expected true or false");
    }
  }
  return h;
}

}  // namespace

YamlTaskConfig readYamlTaskConfig(EnvParams& p, int num_limbs) {
  YamlTaskConfig c;
  const YAML::Node obs = p.section("observation");
  if (!obs.IsDefined() || obs.IsNull())
    failAt(p.origin("observation"), "env.observation", obs,
           "missing: a YAML task needs the source of every observation entry of its spec");
  c.observation_file = p.origin("observation");
  const YamlFields f(obs, "env.observation", c.observation_file, {"central", "limb"});
  c.central = readBlock(p, f.node("central"), "central", false, num_limbs);
  c.limb = readBlock(p, f.node("limb"), "limb", true, num_limbs);
  c.reward = readReward(p);
  c.termination = readTermination(p);
  c.pose = readPose(p);
  c.actuation = readActuation(p);
  c.reset = readReset(p);
  c.heading = readHeading(p);
  return c;
}

}  // namespace masa::task
