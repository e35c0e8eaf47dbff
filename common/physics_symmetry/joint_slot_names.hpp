// Names for what the symmetry finder proposes, read from the model's own names: the entry name of
// a joint that every limb has ("right_hip_x" and "left_hip_x" give "hip_x", "hip_0".."hip_3" give
// "hip"), which side a name says it is on, and the number that tells legs apart.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace masa::task {

// One identifier per slot, unique among the slots: names_per_slot[s] holds slot s's name in every
// limb (one name for a central slot). The parts that differ between limbs are dropped, tokens
// first ("FR_hip"/"FL_hip" -> "hip"), then, where two slots would share a name, characters
// ("F_hip", "R_hip"), then to limb 0's own name; a slot left with no name is "joint<s>".
std::vector<std::string> slotNames(const std::vector<std::vector<std::string>>& names_per_slot);

// +1 for a name on the right ("right_knee", "r_hip", "FR_calf"), -1 on the left, 0 when it says neither.
int sideOfName(const std::string& name);

// The number that differs between `names` ("hip_0".."hip_3", "finger1_upper") for each name, when
// every name has one at the same place and they are distinct; otherwise nothing.
std::optional<std::vector<int>> limbNumbers(const std::vector<std::string>& names);

// Letters, digits and '_', not starting with a digit: what a spec accepts as a name.
std::string identifier(const std::string& text);

}  // namespace masa::task
