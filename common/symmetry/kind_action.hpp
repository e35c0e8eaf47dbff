// How one group element acts on one instance of an entry kind (the K_i of symmetry_spec.hpp), and
// which kinds are representations of which groups.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "common/symmetry/symmetry_spec.hpp"

namespace masa::sym {

std::optional<EntryKind> entryKindFromName(const std::string& name);
// "invariant, odd, polar_x, ..." for error messages.
std::string validEntryKindNames();

// Empty when `kind` transforms linearly under `group` (every T_i exists and T_N = I); otherwise the
// reason it does not, written for a user who has to fix the spec.
std::string kindUnsupportedReason(EntryKind kind, const Group& group);

// K_i for one instance of `kind` (size x size, size = entryKindSize), built from the angle of
// element i itself so that K_i K_j = K_(i+j mod N) holds to rounding. Requires a supported kind.
Eigen::MatrixXd kindAction(EntryKind kind, const Group& group, int i);

}  // namespace masa::sym
