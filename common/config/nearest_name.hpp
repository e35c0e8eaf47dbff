// "Did you mean": the known name closest to a misspelt one, for error messages.
#pragma once

#include <string>
#include <vector>

namespace masa::config {

// The name of `known` fewest single-character edits (insert, delete, replace, swap two neighbours)
// away from `name`, when that is at most 2 and less than half of `name`; otherwise "".
std::string nearestName(const std::string& name, const std::vector<std::string>& known);

}  // namespace masa::config
