#include "common/symmetry/spec_compiler.hpp"

#include <numeric>

#include "common/symmetry/kind_action.hpp"

namespace masa::sym {
namespace {

const Entry& entryNamed(const std::vector<Entry>& entries, const std::string& name) {
  for (const Entry& e : entries)
    if (e.name == name) return e;
  MASA_CHECK(false, "no entry named '" << name << "'");
}

// Writes factor * K into rows [row, row + K.rows()) and columns [col, col + K.cols()).
void addBlock(std::vector<Triplet>& t, int row, int col, const Eigen::MatrixXd& k, double factor) {
  for (int r = 0; r < k.rows(); ++r)
    for (int c = 0; c < k.cols(); ++c)
      if (k(r, c) != 0.0) t.push_back({row + r, col + c, factor * k(r, c)});
}

}  // namespace

SparseMap compileTransform(const BlockLayout& layout, const Group& group, int i) {
  const int n = group.order;
  MASA_CHECK(i >= 0 && i < n, "element " << i << " outside [0, " << n << ")");
  const int central = layout.centralDim();
  const int limb = layout.limbDim();
  const int dim = central + n * limb;
  std::vector<Triplet> t;

  for (const Entry& e : layout.central) {
    const Eigen::MatrixXd k = kindAction(e.kind, group, i);
    const int s = entryKindSize(e.kind);
    // Under the mirror (i = 1) a swapped entry reads its partner's slot; T_0 stays the identity.
    const int src = (!e.swap_with.empty() && i % 2 == 1) ? entryNamed(layout.central, e.swap_with).offset : e.offset;
    for (int j = 0; j < e.count; ++j) addBlock(t, e.offset + j * s, src + j * s, k, 1.0);
  }

  for (const Entry& e : layout.limb) {
    const Eigen::MatrixXd k = kindAction(e.kind, group, i);
    const int s = entryKindSize(e.kind);
    auto sign = [&](int limb_index) { return e.limb_signs.empty() ? 1.0 : double(e.limb_signs[limb_index]); };
    for (int dst_limb = 0; dst_limb < n; ++dst_limb) {
      const int src_limb = (dst_limb + i) % n;
      const double factor = sign(dst_limb) * sign(src_limb);
      for (int j = 0; j < e.count; ++j)
        addBlock(t, central + dst_limb * limb + e.offset + j * s, central + src_limb * limb + e.offset + j * s, k,
                 factor);
    }
  }
  return SparseMap(dim, dim, t);
}

std::vector<int> orbitClasses(const std::vector<SparseMap>& transforms, int dim) {
  std::vector<int> parent(dim);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const SparseMap& m : transforms) {
    MASA_CHECK(m.rows() == dim && m.cols() == dim, "map is " << m.rows() << "x" << m.cols() << ", expected " << dim);
    for (int r = 0; r < dim; ++r)
      for (int k = m.rowStart()[r]; k < m.rowStart()[r + 1]; ++k) parent[root(r)] = root(m.colIndex()[k]);
  }
  std::vector<int> id_of_root(dim, -1), classes(dim);
  int next = 0;
  for (int d = 0; d < dim; ++d) {
    int& id = id_of_root[root(d)];
    if (id < 0) id = next++;
    classes[d] = id;
  }
  return classes;
}

std::vector<std::string> dimensionNames(const BlockLayout& layout, int num_limbs) {
  std::vector<std::string> names;
  auto add = [&](const std::string& prefix, const std::vector<Entry>& entries) {
    for (const Entry& e : entries)
      for (int j = 0; j < e.size(); ++j) {
        std::string name = prefix + "." + e.name;
        if (e.size() > 1) name.append("[").append(std::to_string(j)).append("]");
        names.push_back(std::move(name));
      }
  };
  add("central", layout.central);
  for (int k = 0; k < num_limbs; ++k) add("limb" + std::to_string(k), layout.limb);
  return names;
}

}  // namespace masa::sym
