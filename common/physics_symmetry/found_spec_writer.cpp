#include "common/physics_symmetry/found_spec_writer.hpp"

#include <filesystem>
#include <set>
#include <sstream>

#include "common/physics_symmetry/joint_slot_names.hpp"

namespace masa::task {
namespace {

const char* kAxisNames[] = {"x", "y", "z"};

// One observation entry: its spec line and where a YAML task reads it.
struct ObsEntry {
  std::string name;
  sym::EntryKind kind = sym::EntryKind::kInvariant;
  std::vector<int> limb_signs;
  YAML::Node source;
};

YAML::Node source(const std::string& type, const std::string& key, const std::string& value) {
  YAML::Node n;
  n["source"] = type;
  n[key] = value;
  n.SetStyle(YAML::EmitterStyle::Flow);
  return n;
}

// Free bodies: height (or position), velocities, and for a robot base its orientation.
void freeBodyEntries(const SymmetryCandidate& c, std::vector<ObsEntry>& out) {
  const bool mirror = c.group.type == sym::GroupType::kReflection;
  // The height alone is linear when the group keeps the vertical: any mirror, a rotation about z.
  const bool height_alone = mirror || c.group.axis == sym::Axis::kZ;
  for (const auto& fj : c.free_joints) {
    const std::string b = identifier(fj.body);
    const bool base = fj.kind == sym::FreeJointKind::kRobotBase;
    if (height_alone && base) {
      YAML::Node n = source("body_pos", "body", fj.body);
      n["components"] = "z";
      out.push_back({b + "_height", sym::EntryKind::kPolarZ, {}, n});
    } else {
      out.push_back({b + "_pos", sym::EntryKind::kVector3, {}, source("body_pos", "body", fj.body)});
    }
    out.push_back({b + "_lin_vel", sym::EntryKind::kVector3, {}, source("body_lin_vel", "body", fj.body)});
    out.push_back({b + "_ang_vel", sym::EntryKind::kAxial3, {}, source("body_ang_vel", "body", fj.body)});
    if (base) {
      // The symmetry relabels the base's limbs, so its quaternion is conjugated: w stays, (x, y, z)
      // turns with the world, and under a mirror picks up det = -1 (an axial vector).
      out.push_back({b + "_quat_w", sym::EntryKind::kInvariant, {}, source("body_quat_w", "body", fj.body)});
      out.push_back({b + "_quat_xyz", mirror ? sym::EntryKind::kAxial3 : sym::EntryKind::kVector3, {},
                     source("body_quat_xyz", "body", fj.body)});
    }
  }
}

// Joint position, velocity and last action of every slot, grouped by quantity as the shipped specs are.
void jointEntries(const std::vector<FoundSlot>& slots, std::vector<ObsEntry>& out) {
  const std::pair<const char*, const char*> quantities[] = {
      {"_pos", "joint_pos"}, {"_vel", "joint_vel"}, {"_action", "last_action"}};
  for (const auto& [suffix, type] : quantities)
    for (const auto& s : slots) out.push_back({s.name + suffix, s.kind, s.limb_signs, source(type, "action", s.name)});
}

// A name already taken in the block gets a number.
void makeUnique(std::vector<ObsEntry>& entries) {
  std::set<std::string> seen;
  for (auto& e : entries) {
    std::string name = e.name;
    for (int k = 2; seen.count(name); ++k) name = e.name + "_" + std::to_string(k);
    e.name = name;
    seen.insert(name);
  }
}

std::vector<ObsEntry> centralObservation(const SymmetryCandidate& c) {
  std::vector<ObsEntry> out;
  SymmetryCandidate bases = c, carried = c;  // robot bases first, carried objects after the joints
  std::erase_if(bases.free_joints, [](const auto& f) { return f.kind != sym::FreeJointKind::kRobotBase; });
  std::erase_if(carried.free_joints, [](const auto& f) { return f.kind == sym::FreeJointKind::kRobotBase; });
  freeBodyEntries(bases, out);
  jointEntries(c.central, out);
  freeBodyEntries(carried, out);
  makeUnique(out);
  return out;
}

std::vector<ObsEntry> limbObservation(const SymmetryCandidate& c) {
  std::vector<ObsEntry> out;
  jointEntries(c.limb, out);
  makeUnique(out);
  return out;
}

std::string signsText(const std::vector<int>& signs) {
  std::string s;
  for (int v : signs) s += (s.empty() ? "" : ", ") + std::to_string(v);
  return "[" + s + "]";
}

template <class E>
void writeEntries(std::ostringstream& o, const char* block, const std::vector<E>& entries) {
  o << "  " << block << ":" << (entries.empty() ? " []" : "") << "\n";
  for (const auto& e : entries) {
    o << "    - {name: " << e.name << ", kind: " << sym::entryKindName(e.kind);
    if (!e.limb_signs.empty()) o << ", limb_signs: " << signsText(e.limb_signs);
    o << "}\n";
  }
}

std::string list(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return "[" + s + "]";
}

}  // namespace

std::string foundSpecYaml(const FoundSymmetries& found, const SymmetryCandidate& c) {
  std::ostringstream o;
  const int n = c.group.order;
  const bool mirror = c.group.type == sym::GroupType::kReflection;
  o << "# Proposed by masa_symmetry find from " << found.model_path << ": " << c.label << ".\n"
    << "# Limbs: " << c.limb_cue << ".\n"
    << "# Joint permutation and signs come from the joints' anchors and\n"
    << "# axes at the written pose (an axis that comes out reversed is a sign). The observation is the\n"
    << "# YAML task's (its sources: masa_symmetry find --task-out). Prove it before use:\n"
    << "#   masa_symmetry find " << found.model_path << " --verify\n"
    << "name: " << found.model_name << "\n"
    << "group: {type: " << (mirror ? "reflection" : "rotation") << ", axis: "
    << kAxisNames[static_cast<int>(c.group.axis)];
  if (!mirror) o << ", order: " << n;
  o << "}\n";
  o << "observation:\n";
  writeEntries(o, "central", centralObservation(c));
  writeEntries(o, "limb", limbObservation(c));
  o << "action:\n";
  writeEntries(o, "central", c.central);
  writeEntries(o, "limb", c.limb);
  o << "mujoco:\n  actuators:\n";
  std::vector<std::string> central;
  for (const auto& s : c.central) central.push_back(s.binding[0]);
  if (!central.empty()) o << "    central: " << list(central) << "\n";
  o << "    limbs:\n";
  for (int k = 0; k < n; ++k) {
    std::vector<std::string> limb;
    for (const auto& s : c.limb) limb.push_back(s.binding[k]);
    o << "      - " << list(limb) << "\n";
  }
  if (!c.free_joints.empty()) {
    o << "  free_joints:\n";
    for (const auto& f : c.free_joints)
      o << "    - {name: " << f.joint << ", kind: "
        << (f.kind == sym::FreeJointKind::kRobotBase ? "robot_base" : "object") << "}\n";
  }
  return o.str();
}

YAML::Node foundTaskEnv(const FoundSymmetries& found, const SymmetryCandidate& c) {
  YAML::Node env;
  env["task_code"] = "yaml";
  env["model_file"] = std::filesystem::absolute(found.model_path).lexically_normal().string();
  YAML::Node central(YAML::NodeType::Map), limb(YAML::NodeType::Map);
  for (const auto& e : centralObservation(c)) central[e.name] = e.source;
  for (const auto& e : limbObservation(c)) limb[e.name] = e.source;
  env["observation"]["central"] = central;
  env["observation"]["limb"] = limb;
  // Random joint angles and velocities, so that the verifier's states exercise every joint.
  env["reset"]["joint_noise"] = 0.1;
  env["reset"]["velocity_noise"] = 0.1;
  return env;
}

std::string foundTaskYaml(const FoundSymmetries& found, const SymmetryCandidate& c, const std::string& spec_path) {
  YAML::Node root;
  root["spec"] = spec_path;
  root["env"] = foundTaskEnv(found, c);
  YAML::Emitter out;
  out << root;
  return "# A YAML task over the spec masa_symmetry find proposed for " + found.model_path +
         " (docs/yaml_task.md):\n# add a reward, terminations and a heading for training.\n" + out.c_str() + "\n";
}

}  // namespace masa::task
