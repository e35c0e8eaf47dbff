// Small hand-written symmetry specs and numeric helpers shared by the model tests.
#pragma once

#include <functional>
#include <string>

#include "common/core/types.hpp"
#include "common/symmetry/symmetry_spec.hpp"

namespace masa::test {

// Humanoid-like mirror about the x-z plane: every entry kind a reflection supports.
inline const char* kMirrorSpec = R"(
name: mini_mirror
group: {type: reflection, axis: y}
observation:
  central:
    - {name: torso_y, kind: polar_y}
    - {name: torso_z, kind: polar_z}
    - {name: torso_vel, kind: vector3}
    - {name: torso_angvel, kind: axial3}
    - {name: torso_quat, kind: quaternion}
    - {name: waist, kind: odd, count: 2}
    - {name: pitch, kind: invariant}
  limb:
    - {name: hip_x, kind: odd}
    - {name: knee, kind: invariant}
    - {name: foot_pos, kind: vector3}
action:
  central:
    - {name: abdomen_z, kind: odd}
    - {name: abdomen_y, kind: invariant}
  limb:
    - {name: hip_x, kind: odd}
    - {name: knee, kind: invariant}
)";

// TriFinger-like C3 rotation about z with a quaternion and rotating vectors; no central action.
inline const char* kC3Spec = R"(
name: mini_c3
group: {type: rotation, axis: z, order: 3}
observation:
  central:
    - {name: cube_pos, kind: vector3}
    - {name: cube_quat, kind: quaternion}
    - {name: goal_xy, kind: vector2}
    - {name: delay, kind: invariant}
  limb:
    - {name: joints, kind: invariant, count: 3}
    - {name: tip_pos, kind: vector3}
action:
  central: []
  limb:
    - {name: joints, kind: invariant, count: 3}
)";

// Ant-like C4 rotation with alternating ankle sign conventions and a central action.
inline const char* kC4Spec = R"(
name: mini_c4
group: {type: rotation, axis: z, order: 4}
observation:
  central:
    - {name: torso_pos, kind: vector3}
    - {name: gravity, kind: vector3}
    - {name: yaw_rate, kind: axial_z}
  limb:
    - {name: hip, kind: invariant}
    - {name: ankle, kind: invariant, limb_signs: [1, -1, 1, -1]}
action:
  central:
    - {name: twist, kind: invariant}
  limb:
    - {name: hip, kind: invariant}
    - {name: ankle, kind: invariant, limb_signs: [1, -1, 1, -1]}
)";

inline sym::SymmetrySpec spec(const char* yaml, const std::string& name) {
  return sym::SymmetrySpec::parseString(yaml, name);
}

template <typename S>
Mat<S> randomMatrix(int rows, int cols, Rng& rng, double scale = 1.0, double shift = 0.0) {
  std::normal_distribution<double> n(shift, scale);
  Mat<S> m(rows, cols);
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index i = 0; i < m.rows(); ++i) m(i, j) = static_cast<S>(n(rng));
  return m;
}

struct GradientCheckResult {
  double max_relative_error = 0;
  int worst_index = -1;
  double analytic_norm = 0;
};

// Compares an analytic gradient with central differences of `loss` over every entry of `x`.
// Relative error |a - n| / max(|a|, |n|, floor): the floor keeps rounding noise on gradients near
// zero from counting as relative error.
inline GradientCheckResult checkGradient(Eigen::Ref<Vec<double>> x, const Vec<double>& analytic,
                                         const std::function<double()>& loss, double h = 1e-6, double floor = 1e-5) {
  GradientCheckResult r;
  r.analytic_norm = analytic.norm();
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    const double saved = x(k);
    x(k) = saved + h;
    const double up = loss();
    x(k) = saved - h;
    const double down = loss();
    x(k) = saved;
    const double numeric = (up - down) / (2 * h);
    const double err = std::abs(analytic(k) - numeric) / std::max({std::abs(analytic(k)), std::abs(numeric), floor});
    if (err > r.max_relative_error) {
      r.max_relative_error = err;
      r.worst_index = static_cast<int>(k);
    }
  }
  return r;
}

}  // namespace masa::test
