#include "common/symmetry/kind_action.hpp"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <numbers>
#include <utility>

#include "common/core/check.hpp"

namespace masa::sym {
namespace {

struct KindInfo {
  EntryKind kind;
  const char* name;
  int size;
};

constexpr std::array<KindInfo, 12> kKinds{{
    {EntryKind::kInvariant, "invariant", 1},
    {EntryKind::kOdd, "odd", 1},
    {EntryKind::kPolarX, "polar_x", 1},
    {EntryKind::kPolarY, "polar_y", 1},
    {EntryKind::kPolarZ, "polar_z", 1},
    {EntryKind::kAxialX, "axial_x", 1},
    {EntryKind::kAxialY, "axial_y", 1},
    {EntryKind::kAxialZ, "axial_z", 1},
    {EntryKind::kVector3, "vector3", 3},
    {EntryKind::kAxial3, "axial3", 3},
    {EntryKind::kVector2, "vector2", 2},
    {EntryKind::kQuaternion, "quaternion", 4},
}};

const KindInfo& info(EntryKind kind) {
  for (const KindInfo& k : kKinds)
    if (k.kind == kind) return k;
  MASA_CHECK(false, "unknown EntryKind " << static_cast<int>(kind));
}

char axisName(Axis a) { return "xyz"[static_cast<int>(a)]; }

// The coordinate a single-component kind refers to, and whether it is axial; nullopt otherwise.
std::optional<std::pair<int, bool>> singleComponent(EntryKind kind) {
  switch (kind) {
    case EntryKind::kPolarX: return std::pair{0, false};
    case EntryKind::kPolarY: return std::pair{1, false};
    case EntryKind::kPolarZ: return std::pair{2, false};
    case EntryKind::kAxialX: return std::pair{0, true};
    case EntryKind::kAxialY: return std::pair{1, true};
    case EntryKind::kAxialZ: return std::pair{2, true};
    default: return std::nullopt;
  }
}

// cos/sin of multiples of 2*pi/N leave residues like 6e-17 where the exact value is 0 or +-1;
// snapping them keeps C4 and C2 maps exact signed permutations and their sparsity honest.
double snap(double v) {
  constexpr double kTol = 1e-14;
  if (std::abs(v) < kTol) return 0.0;
  if (std::abs(v - 1.0) < kTol) return 1.0;
  if (std::abs(v + 1.0) < kTol) return -1.0;
  return v;
}

Eigen::Matrix3d mirrorMatrix(Axis normal) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m(static_cast<int>(normal), static_cast<int>(normal)) = -1.0;
  return m;
}

Eigen::Matrix3d rotationMatrix(Axis axis, double angle) {
  const Eigen::Vector3d u = Eigen::Vector3d::Unit(static_cast<int>(axis));
  return Eigen::AngleAxisd(angle, u).toRotationMatrix().unaryExpr(&snap);
}

// Matrix of q -> p * q on (w, x, y, z).
Eigen::Matrix4d leftMultiplication(const Eigen::Vector4d& p) {
  const double w = p(0), x = p(1), y = p(2), z = p(3);
  Eigen::Matrix4d l;
  l << w, -x, -y, -z,  //
      x, w, -z, y,     //
      y, z, w, -x,     //
      z, -y, x, w;
  return l;
}

Eigen::MatrixXd reflectionAction(EntryKind kind, Axis normal) {
  const Eigen::Matrix3d m = mirrorMatrix(normal);
  if (auto comp = singleComponent(kind)) {
    const double d = m(comp->first, comp->first);
    return Eigen::MatrixXd::Constant(1, 1, comp->second ? -d : d);
  }
  switch (kind) {
    case EntryKind::kInvariant: return Eigen::MatrixXd::Identity(1, 1);
    case EntryKind::kOdd: return -Eigen::MatrixXd::Identity(1, 1);
    case EntryKind::kVector3: return m;
    // An axial vector is a cross product of two polar ones: it picks up det(M) = -1.
    case EntryKind::kAxial3: return -m;
    case EntryKind::kVector2: return m.topLeftCorner<2, 2>();
    case EntryKind::kQuaternion: {
      // The mirrored orientation M R M is the rotation R conjugated by the half turn about the
      // normal (M = -half turn), so the vector part transforms as an axial vector.
      Eigen::Matrix4d q = Eigen::Matrix4d::Identity();
      q.bottomRightCorner<3, 3>() = -m;
      return q;
    }
    default: break;
  }
  MASA_CHECK(false, "no reflection action for kind " << entryKindName(kind));
}

Eigen::MatrixXd rotationAction(EntryKind kind, const Group& g, int i) {
  const double two_pi = 2.0 * std::numbers::pi;
  const double angle = -two_pi * i / g.order;
  switch (kind) {
    case EntryKind::kInvariant: return Eigen::MatrixXd::Identity(1, 1);
    case EntryKind::kOdd: return Eigen::MatrixXd::Constant(1, 1, i % 2 == 0 ? 1.0 : -1.0);
    case EntryKind::kPolarX:
    case EntryKind::kPolarY:
    case EntryKind::kPolarZ:
    case EntryKind::kAxialX:
    case EntryKind::kAxialY:
    case EntryKind::kAxialZ:
      // Only the component along the axis is closed under the rotation, and it is unchanged.
      return Eigen::MatrixXd::Identity(1, 1);
    case EntryKind::kVector3:
    case EntryKind::kAxial3: return rotationMatrix(g.axis, angle);
    case EntryKind::kVector2: return rotationMatrix(Axis::kZ, angle).topLeftCorner<2, 2>();
    case EntryKind::kQuaternion: {
      // phi_i = -2*pi*i*(N+1)/N is the same rotation as -2*pi*i/N, but its half angle at i = N is
      // -pi*(N+1), a multiple of 2*pi for odd N, so p_N = +1 and T_N = I (not -I).
      const double half = 0.5 * angle * (g.order + 1);
      Eigen::Vector4d p = Eigen::Vector4d::Zero();
      p(0) = std::cos(half);
      p(1 + static_cast<int>(g.axis)) = std::sin(half);
      return leftMultiplication(p.unaryExpr(&snap));
    }
  }
  MASA_CHECK(false, "no rotation action for kind " << entryKindName(kind));
}

}  // namespace

int entryKindSize(EntryKind kind) { return info(kind).size; }
std::string entryKindName(EntryKind kind) { return info(kind).name; }

std::optional<EntryKind> entryKindFromName(const std::string& name) {
  for (const KindInfo& k : kKinds)
    if (name == k.name) return k.kind;
  return std::nullopt;
}

std::string validEntryKindNames() {
  std::string s;
  for (const KindInfo& k : kKinds) s += (s.empty() ? "" : ", ") + std::string(k.name);
  return s;
}

std::string kindUnsupportedReason(EntryKind kind, const Group& g) {
  if (g.type == GroupType::kReflection) return "";
  std::string group_name = "C";  // appended piecewise: GCC 12 warns falsely on "lit" + std::string&&
  group_name.append(std::to_string(g.order)).append(" rotation about ").push_back(axisName(g.axis));
  if (kind == EntryKind::kOdd && g.order % 2 == 1)
    return "kind 'odd' flips the sign at every generator step, which is not a representation of the odd-order " +
           group_name + " (T_N would be -I, not I); use 'invariant', or per-limb signs via limb_signs";
  if (auto comp = singleComponent(kind); comp && comp->first != static_cast<int>(g.axis))
    return "kind '" + entryKindName(kind) + "' is a single component perpendicular to the axis of the " + group_name +
           ", which mixes it with the other perpendicular component; observe the whole vector (vector3, axial3, or "
           "vector2 for a rotation about z)";
  if (kind == EntryKind::kVector2 && g.axis != Axis::kZ)
    return std::string("kind 'vector2' holds (x, y), which a rotation about ") + axisName(g.axis) +
           " mixes with z; use vector3, or rotate about z";
  if (kind == EntryKind::kQuaternion && g.order % 2 == 0)
    return "kind 'quaternion' under the even-order " + group_name +
           " has no linear lift: left multiplication by the yaw quaternion p gives p^N = -1, so T_N = -I, and no other "
           "choice of signs fixes that. Observe projected gravity / heading vectors (vector3) instead; for a floating "
           "base whose frame the symmetry relabels, the orientation transforms by conjugation (w invariant, (x, y, z) "
           "a vector3), so write it as {kind: invariant} + {kind: vector3}";
  return "";
}

Eigen::MatrixXd kindAction(EntryKind kind, const Group& g, int i) {
  MASA_CHECK(g.order >= 2, "group order " << g.order);
  MASA_CHECK(i >= 0 && i < g.order, "element " << i << " outside [0, " << g.order << ")");
  MASA_CHECK(kindUnsupportedReason(kind, g).empty(), kindUnsupportedReason(kind, g));
  const int n = entryKindSize(kind);
  if (i == 0) return Eigen::MatrixXd::Identity(n, n);
  if (g.type == GroupType::kReflection) return reflectionAction(kind, g.axis);
  return rotationAction(kind, g, i);
}

}  // namespace masa::sym
