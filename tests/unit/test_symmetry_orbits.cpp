// Orbit classes: dimensions that any T_i mixes share a class, all others stay apart.
#include <gtest/gtest.h>

#include <set>

#include "common/symmetry/symmetry_spec.hpp"

namespace masa::sym {
namespace {

int numClasses(const std::vector<int>& classes) {
  return static_cast<int>(std::set<int>(classes.begin(), classes.end()).size());
}

TEST(SymmetryOrbitClasses, RotatingVectorComponentsShareAClassAxisComponentApart) {
  const SymmetrySpec spec = SymmetrySpec::parseString(R"(
name: c3
group: {type: rotation, axis: z, order: 3}
observation:
  central: [{name: p, kind: vector3}, {name: q, kind: quaternion}, {name: t, kind: invariant}]
  limb: [{name: a, kind: invariant}, {name: b, kind: invariant}]
action: {limb: [{name: u, kind: invariant}]}
)");
  const auto& c = spec.obsClasses();
  EXPECT_EQ(c[0], c[1]);  // p.x, p.y
  EXPECT_NE(c[0], c[2]);  // p.z is invariant under a rotation about z
  EXPECT_EQ(c[3], c[6]);  // yaw left multiplication mixes q.w with q.z
  EXPECT_EQ(c[4], c[5]);  // and q.x with q.y
  EXPECT_NE(c[3], c[4]);
  // The same limb entry across limbs is one class; different entries are not.
  EXPECT_EQ(c[8], c[10]);
  EXPECT_EQ(c[8], c[12]);
  EXPECT_NE(c[8], c[9]);
  EXPECT_EQ(c[9], c[13]);
  // Classes are numbered 0.. in order of first appearance.
  const std::vector<int> expected{0, 0, 1, 2, 3, 3, 2, 4, 5, 6, 5, 6, 5, 6};
  EXPECT_EQ(c, expected);
  EXPECT_EQ(numClasses(spec.actClasses()), 1);
}

TEST(SymmetryOrbitClasses, SwappedEntriesShareAClassInvariantEntriesAreAlone) {
  const SymmetrySpec spec = SymmetrySpec::parseString(R"(
name: mirror
group: {type: reflection, axis: y}
observation:
  central:
    - {name: l, kind: odd, swap_with: r}
    - {name: r, kind: odd}
    - {name: k1, kind: invariant}
    - {name: k2, kind: invariant}
    - {name: p, kind: vector3}
action: {central: [{name: u, kind: odd}, {name: v, kind: invariant}]}
)");
  const auto& c = spec.obsClasses();
  EXPECT_EQ(c[0], c[1]);
  EXPECT_NE(c[2], c[3]);
  // A mirror only flips signs of a polar vector's components: it mixes none of them.
  EXPECT_EQ(numClasses(c), 1 + 2 + 3);
  EXPECT_EQ(numClasses(spec.actClasses()), 2);
}

}  // namespace
}  // namespace masa::sym
