// Writes what the symmetry finder proposes as files a user keeps: the symmetry spec (the format of
// configs/specs/*.yaml, docs/symmetry_spec.md) and the `env` section of a YAML task
// (docs/yaml_task.md) that fills its observation from the model.
//
// The observation is the one a YAML task can observe of any robot, with each entry's kind fixed by
// how its source moves under the group: for a robot base its height (the whole position under a
// rotation about x or y), world linear and angular velocity and orientation quaternion; the same
// for every carried object but its orientation (not linear under a rotation); then for every
// actuated joint its position, velocity and last action, with its action's kind and limb_signs.
// A task that observes anything else (a goal, a heading, a route) adds its own entries.
#pragma once

#include <string>

#include <yaml-cpp/yaml.h>

#include "common/physics_symmetry/symmetry_finder.hpp"

namespace masa::task {

// The spec's YAML text, comments included (how it was found, what to check).
std::string foundSpecYaml(const FoundSymmetries& found, const SymmetryCandidate& candidate);

// The env section of a YAML task over the found spec: task_code yaml, the model (absolute path),
// the observation sources of every spec entry, and a reset that moves the joints.
YAML::Node foundTaskEnv(const FoundSymmetries& found, const SymmetryCandidate& candidate);

// A whole task config file: `spec: <spec_path>` and the env above, for masa_verify --task and masa_train.
std::string foundTaskYaml(const FoundSymmetries& found, const SymmetryCandidate& candidate,
                          const std::string& spec_path);

}  // namespace masa::task
