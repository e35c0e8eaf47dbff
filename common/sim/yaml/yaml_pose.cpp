#include "common/sim/yaml/yaml_pose.hpp"

#include <algorithm>
#include <cmath>

#include "common/core/config_error.hpp"

namespace masa::task {
namespace {

// Sets every action of the entry called `name` (central, and the same slot of every limb).
bool setEntry(const sym::SymmetrySpec& s, const std::string& name, double value, std::vector<double>& pose) {
  bool found = false;
  for (const sym::Entry& e : s.actionLayout().central)
    if (e.name == name) {
      std::fill(pose.begin() + e.offset, pose.begin() + e.offset + e.size(), value);
      found = true;
    }
  for (int limb = 0; limb < s.numAgents(); ++limb)
    for (const sym::Entry& e : s.actionLayout().limb)
      if (e.name == name) {
        const int first = s.actCentralDim() + limb * s.actLimbDim() + e.offset;
        std::fill(pose.begin() + first, pose.begin() + first + e.size(), value);
        found = true;
      }
  return found;
}

}  // namespace

std::vector<double> resolvePose(const YamlTaskConfig& config, const Task& task) {
  const mjModel* m = task.model();
  const sym::SymmetrySpec& s = task.spec();
  const std::vector<int>& joints = task.actionJoints();
  std::vector<double> pose(task.actDim(), 0.0);
  for (int k = 0; k < task.actDim(); ++k)
    if (joints[k] >= 0) pose[k] = m->qpos0[m->jnt_qposadr[joints[k]]];
  for (const PoseJointConfig& p : config.pose) {
    if (setEntry(s, p.name, p.value, pose)) continue;
    const int j = mj_name2id(m, mjOBJ_JOINT, p.name.c_str());
    const auto at = std::find(joints.begin(), joints.end(), j);
    if (j < 0 || at == joints.end()) {
      std::string known;
      for (const auto* block : {&s.actionLayout().central, &s.actionLayout().limb})
        for (const sym::Entry& e : *block) known += (known.empty() ? "" : ", ") + e.name;
      throw ConfigError(p.file, p.path,
                        "'" + p.name + "' is neither an action entry of " + s.source() + " (" + known +
                            ") nor an actuated joint of " + task.mujocoModel().path());
    }
    pose[at - joints.begin()] = p.value;
  }
  const Eigen::Map<const Eigen::VectorXd> v(pose.data(), task.actDim());
  for (int i = 1; i < s.numAgents(); ++i) {
    Eigen::VectorXd tv(task.actDim());
    s.actTransform(i).apply<double>(v, tv);
    for (int k = 0; k < task.actDim(); ++k)
      if (std::abs(tv[k] - v[k]) > 1e-12)
        throw ConfigError(config.pose.empty() ? config.observation_file : config.pose.front().file, "env.pose",
                          "the pose is not symmetric: group element " + std::to_string(i) + " needs " +
                              s.actNames()[k] + " at " + std::to_string(tv[k]) + ", the pose has " +
                              std::to_string(v[k]) + " (a limb's pose is the image of another's: mind the signs)");
  }
  return pose;
}

}  // namespace masa::task
