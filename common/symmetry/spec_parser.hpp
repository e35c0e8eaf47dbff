// YAML -> validated group and block layouts. Every problem is a masa::ConfigError naming the source
// and the key path ("observation.limb[2].kind"); the format is documented in docs/symmetry_spec.md.
#pragma once

#include <string>

#include "common/symmetry/symmetry_spec.hpp"

namespace masa::sym {

struct ParsedSpec {
  std::string name;
  Group group;
  BlockLayout observation;
  BlockLayout action;
  MujocoBinding mujoco;
};

// Entries come back with offsets set, and a swap_with pair names each other on both entries.
ParsedSpec parseSpecYaml(const YAML::Node& root, const std::string& source);

}  // namespace masa::sym
