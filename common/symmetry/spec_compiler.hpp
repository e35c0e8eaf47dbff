// Validated layout + group -> the sparse maps T_i, their orbit classes and per-dimension names.
#pragma once

#include <string>
#include <vector>

#include "common/symmetry/sparse_map.hpp"
#include "common/symmetry/symmetry_spec.hpp"

namespace masa::sym {

// T_i for element i in [0, N), per the formula of symmetry_spec.hpp.
SparseMap compileTransform(const BlockLayout& layout, const Group& group, int i);

// Union-find over the nonzeros of every map: dimensions any T_i mixes share a class. Classes are
// numbered 0.. in order of their first dimension.
std::vector<int> orbitClasses(const std::vector<SparseMap>& transforms, int dim);

// "central.<name>" / "limb<k>.<name>" for one-value entries, with "[j]" appended per value otherwise.
std::vector<std::string> dimensionNames(const BlockLayout& layout, int num_limbs);

}  // namespace masa::sym
