// The reference pose of a YAML task (env.pose): where the reset starts each actuated joint, the
// centre of the PD targets, and what `from_pose` observations are measured from. Given by action
// entry (a limb entry sets that joint in every limb) or by joint name; other joints keep the
// model's qpos0. The pose must be symmetric itself (T_i maps it onto itself), or the PD targets
// and the offsets around it would break the symmetry the spec claims.
#pragma once

#include <vector>

#include "common/sim/task.hpp"
#include "common/sim/yaml/yaml_task_config.hpp"

namespace masa::task {

// One position per action (its joint's; 0 for an action that drives no joint). ConfigError naming
// the pose key for an unknown name, or for a pose the group does not keep.
std::vector<double> resolvePose(const YamlTaskConfig& config, const Task& task);

}  // namespace masa::task
