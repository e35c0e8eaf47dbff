// Entry kinds, limb shifts, limb_signs and swap_with, checked numerically on small hand-written specs.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>

#include "common/symmetry/symmetry_spec.hpp"

namespace masa::sym {
namespace {

constexpr double kPi = std::numbers::pi;

Eigen::VectorXd apply(const SparseMap& m, const Eigen::VectorXd& x) {
  Eigen::MatrixXd y(m.rows(), 1);
  m.apply<double>(x, y);
  return y.col(0);
}

Eigen::Quaterniond quat(const Eigen::VectorXd& v, int at) { return {v(at), v(at + 1), v(at + 2), v(at + 3)}; }

// A unit quaternion equals q or -q (the same rotation).
void expectSameRotation(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  EXPECT_NEAR(std::abs(a.coeffs().dot(b.coeffs())), 1.0, 1e-12) << a.coeffs().transpose() << " vs "
                                                                 << b.coeffs().transpose();
}

const char* kMirrorY = R"(
name: mirror
group: {type: reflection, axis: y}
observation:
  central:
    - {name: p, kind: vector3}
    - {name: w, kind: axial3}
    - {name: q, kind: quaternion}
    - {name: px, kind: polar_x}
    - {name: py, kind: polar_y}
    - {name: ax, kind: axial_x}
    - {name: ay, kind: axial_y}
    - {name: v2, kind: vector2}
    - {name: o, kind: odd, count: 2}
action:
  limb:
    - {name: j, kind: invariant}
)";

TEST(SymmetryKinds, MirrorFlipsPolarNormalComponentAndAxialTangentialOnes) {
  const SymmetrySpec spec = SymmetrySpec::parseString(kMirrorY, "mirror.yaml");
  ASSERT_EQ(spec.obsDim(), 3 + 3 + 4 + 4 + 2 + 2);
  Eigen::VectorXd o = Eigen::VectorXd::Zero(spec.obsDim());
  o.head(3) << 1, 2, 3;
  o.segment(3, 3) << 1, 2, 3;
  o.segment(10, 4) << 5, 6, 7, 8;
  o.segment(14, 2) << 1, 2;
  o.tail(2) << 4, -9;
  const Eigen::VectorXd m = apply(spec.obsTransform(1), o);
  EXPECT_EQ(Eigen::Vector3d(m.head(3)), Eigen::Vector3d(1, -2, 3));    // polar: (x, -y, z)
  EXPECT_EQ(Eigen::Vector3d(m.segment(3, 3)), Eigen::Vector3d(-1, 2, -3));  // axial: -(x, -y, z)
  EXPECT_EQ(m(10), 5);   // polar_x keeps
  EXPECT_EQ(m(11), -6);  // polar_y flips
  EXPECT_EQ(m(12), -7);  // axial_x flips
  EXPECT_EQ(m(13), 8);   // axial_y keeps
  EXPECT_EQ(Eigen::Vector2d(m.segment(14, 2)), Eigen::Vector2d(1, -2));
  EXPECT_EQ(Eigen::Vector2d(m.tail(2)), Eigen::Vector2d(-4, 9));
  EXPECT_EQ(apply(spec.obsTransform(0), o), o);
}

TEST(SymmetryKinds, MirrorMapsQuaternionToMirroredRotation) {
  const SymmetrySpec spec = SymmetrySpec::parseString(kMirrorY, "mirror.yaml");
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()));
  Eigen::VectorXd o = Eigen::VectorXd::Zero(spec.obsDim());
  o.segment(6, 4) << q.w(), q.x(), q.y(), q.z();
  const Eigen::Matrix3d mirror = Eigen::Vector3d(1, -1, 1).asDiagonal();
  // The mirrored body's orientation: reflect the world, then relabel the body's sides (M R M).
  const Eigen::Quaterniond expected(Eigen::Matrix3d(mirror * q.toRotationMatrix() * mirror));
  expectSameRotation(quat(apply(spec.obsTransform(1), o), 6), expected);
}

TEST(SymmetryKinds, MirrorAboutXNegatesX) {
  const SymmetrySpec spec = SymmetrySpec::parseString(R"(
name: mx
group: {type: reflection, axis: x, order: 2}
observation: {central: [{name: p, kind: vector3}, {name: w, kind: axial3}]}
action: {central: [{name: a, kind: polar_x}]}
)");
  Eigen::VectorXd o(6);
  o << 1, 2, 3, 1, 2, 3;
  Eigen::VectorXd expected(6);
  expected << -1, 2, 3, 1, -2, -3;
  EXPECT_EQ(apply(spec.obsTransform(1), o), expected);
  EXPECT_EQ(apply(spec.actTransform(1), Eigen::VectorXd::Constant(1, 2.0))(0), -2.0);
}

const char* kC3Spec = R"(
name: c3
group: {type: rotation, axis: z, order: 3}
observation:
  central:
    - {name: p, kind: vector3}
    - {name: q, kind: quaternion}
    - {name: v2, kind: vector2}
    - {name: h, kind: polar_z}
  limb:
    - {name: a, kind: invariant}
    - {name: b, kind: axial3}
action:
  limb: [{name: u, kind: invariant}]
)";

TEST(SymmetryKinds, RotationTurnsVectorsByMinusTwoPiIOverN) {
  const SymmetrySpec spec = SymmetrySpec::parseString(kC3Spec, "c3.yaml");
  ASSERT_EQ(spec.obsDim(), 3 + 4 + 2 + 1 + 3 * 4);
  Eigen::VectorXd o = Eigen::VectorXd::Random(spec.obsDim());
  for (int i = 0; i < 3; ++i) {
    const Eigen::Matrix3d r(Eigen::AngleAxisd(-2 * kPi * i / 3, Eigen::Vector3d::UnitZ()));
    const Eigen::VectorXd t = apply(spec.obsTransform(i), o);
    EXPECT_LT((t.head(3) - r * o.head(3)).norm(), 1e-14) << "i=" << i;
    EXPECT_LT((t.segment(7, 2) - r.topLeftCorner<2, 2>() * o.segment(7, 2)).norm(), 1e-14) << "i=" << i;
    EXPECT_EQ(t(9), o(9));  // the component along the axis is invariant
  }
  // Limb 1 sits at +120 deg: turning the world by -120 deg puts a point there onto limb 0's angle.
  Eigen::VectorXd at_limb1 = Eigen::VectorXd::Zero(spec.obsDim());
  at_limb1.head(3) << std::cos(2 * kPi / 3), std::sin(2 * kPi / 3), 0.5;
  EXPECT_LT((apply(spec.obsTransform(1), at_limb1).head(3) - Eigen::Vector3d(1, 0, 0.5)).norm(), 1e-15);
}

TEST(SymmetryKinds, RotationLeftMultipliesQuaternionByYaw) {
  const SymmetrySpec spec = SymmetrySpec::parseString(kC3Spec, "c3.yaml");
  const Eigen::Quaterniond q(Eigen::AngleAxisd(1.1, Eigen::Vector3d(-0.2, 0.9, 0.4).normalized()));
  Eigen::VectorXd o = Eigen::VectorXd::Zero(spec.obsDim());
  o.segment(3, 4) << q.w(), q.x(), q.y(), q.z();
  for (int i = 0; i < 3; ++i) {
    const Eigen::Matrix3d r(Eigen::AngleAxisd(-2 * kPi * i / 3, Eigen::Vector3d::UnitZ()));
    const Eigen::Quaterniond t = quat(apply(spec.obsTransform(i), o), 3);
    EXPECT_LT((t.toRotationMatrix() - r * q.toRotationMatrix()).cwiseAbs().maxCoeff(), 1e-14) << "i=" << i;
    EXPECT_NEAR(t.norm(), 1.0, 1e-15);
  }
}

TEST(SymmetryKinds, QuaternionLiftGivesIdentityAfterNStepsForOddOrder) {
  // Applying the generator N times must give +q, not -q (that is what the odd-N lift is for).
  const SymmetrySpec spec = SymmetrySpec::parseString(R"(
name: c5x
group: {type: rotation, axis: x, order: 5}
observation: {central: [{name: q, kind: quaternion}]}
action: {central: [{name: u, kind: invariant}]}
)");
  const Eigen::MatrixXd g = spec.obsTransform(1).toDense();
  Eigen::MatrixXd power = Eigen::MatrixXd::Identity(4, 4);
  for (int k = 0; k < 5; ++k) power = g * power;
  EXPECT_LT((power - Eigen::MatrixXd::Identity(4, 4)).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(SymmetryKinds, LimbBlocksShiftSoAgentIsLimbComesFirst) {
  const SymmetrySpec spec = SymmetrySpec::parseString(kC3Spec, "c3.yaml");
  const int c = spec.obsCentralDim(), l = spec.obsLimbDim();
  Eigen::VectorXd o = Eigen::VectorXd::Zero(spec.obsDim());
  for (int k = 0; k < 3; ++k) {
    o(c + k * l) = 10 + k;                    // invariant entry a of limb k
    o.segment(c + k * l + 1, 3) << 0, 0, k;  // axial3 entry b of limb k, along the axis
  }
  for (int i = 0; i < 3; ++i) {
    const Eigen::VectorXd t = apply(spec.obsTransform(i), o);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(t(c + k * l), 10 + (k + i) % 3) << "i=" << i << " k=" << k;
      EXPECT_EQ(t(c + k * l + 3), (k + i) % 3) << "i=" << i << " k=" << k;
    }
  }
  const Eigen::VectorXd a = apply(spec.actTransform(2), Eigen::Vector3d(0, 1, 2));
  EXPECT_EQ(Eigen::Vector3d(a), Eigen::Vector3d(2, 0, 1));
}

TEST(SymmetryKinds, LimbSignsConvertToCommonConventionAroundTheShift) {
  const SymmetrySpec spec = SymmetrySpec::parseString(R"(
name: c4
group: {type: rotation, axis: z, order: 4}
observation: {limb: [{name: ankle, kind: invariant, limb_signs: [1, -1, -1, 1]}, {name: s, kind: odd}]}
action: {limb: [{name: ankle, kind: invariant, limb_signs: [1, -1, -1, 1]}]}
)");
  const Eigen::Vector4d s(1, -1, -1, 1);
  const Eigen::Vector4d x(1, 2, 3, 4);
  for (int i = 0; i < 4; ++i) {
    const Eigen::VectorXd t = apply(spec.actTransform(i), x);
    // limb k' = s_k * (s_(k+i) * x_(k+i)): the common-convention values s_k x_k shift cyclically.
    for (int k = 0; k < 4; ++k) EXPECT_EQ(t(k), s(k) * s((k + i) % 4) * x((k + i) % 4)) << "i=" << i;
  }
  EXPECT_EQ(Eigen::Vector4d(apply(spec.actTransform(1), x)), Eigen::Vector4d(-2, 3, -4, 1));
  // An odd entry under C4 flips at odd steps only; limb 0's value lands in limb (4 - i) % 4.
  Eigen::VectorXd o = Eigen::VectorXd::Zero(8);
  o(1) = 5;  // entry s of limb 0 (limb blocks are [ankle, s])
  EXPECT_EQ(apply(spec.obsTransform(1), o)(2 * 3 + 1), -5);
  EXPECT_EQ(apply(spec.obsTransform(2), o)(2 * 2 + 1), 5);
  EXPECT_EQ(apply(spec.obsTransform(3), o)(2 * 1 + 1), -5);
}

TEST(SymmetryKinds, SwapWithExchangesPartnersWithTheirKindSign) {
  const SymmetrySpec spec = SymmetrySpec::parseString(R"(
name: swaps
group: {type: reflection, axis: y}
observation:
  central:
    - {name: left_contact, kind: invariant, swap_with: right_contact}
    - {name: right_contact, kind: invariant}
    - {name: left_roll, kind: odd, count: 2}
    - {name: right_roll, kind: odd, count: 2, swap_with: left_roll}
    - {name: keep, kind: invariant}
action: {central: [{name: u, kind: odd}]}
)");
  EXPECT_EQ(spec.observationLayout().central[0].swap_with, "right_contact");
  EXPECT_EQ(spec.observationLayout().central[1].swap_with, "left_contact");  // implied by the partner
  Eigen::VectorXd o(7);
  o << 1, 2, 3, 4, 5, 6, 7;
  Eigen::VectorXd expected(7);
  expected << 2, 1, -5, -6, -3, -4, 7;
  EXPECT_EQ(apply(spec.obsTransform(1), o), expected);
  EXPECT_EQ(apply(spec.obsTransform(0), o), o);
}

TEST(SymmetryKinds, DimensionNamesFollowBlockEntryAndComponent) {
  const SymmetrySpec spec = SymmetrySpec::parseString(kC3Spec, "c3.yaml");
  const auto& n = spec.obsNames();
  EXPECT_EQ(n[0], "central.p[0]");
  EXPECT_EQ(n[6], "central.q[3]");
  EXPECT_EQ(n[9], "central.h");
  EXPECT_EQ(n[10], "limb0.a");
  EXPECT_EQ(n[13], "limb0.b[2]");
  EXPECT_EQ(n[14], "limb1.a");
  EXPECT_EQ(n.back(), "limb2.b[2]");
  EXPECT_EQ(spec.actNames()[2], "limb2.u");
}

}  // namespace
}  // namespace masa::sym
