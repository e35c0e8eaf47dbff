// The spatial action of group element i: the 3x3 orthogonal map that T_i applies to a polar
// vector (rotation by -2*pi*i/N about the axis, or the mirror for odd i of a reflection), and for
// rotations the unit quaternion of that rotation. Used where whole simulator states are transformed.
#pragma once

#include <Eigen/Geometry>

#include "common/symmetry/symmetry_spec.hpp"

namespace masa::sym {

Eigen::Matrix3d spatialMap(const Group& group, int i);
// True when element i reverses orientation (a mirror).
bool isMirror(const Group& group, int i);
// Rotation part as a quaternion (identity for a mirror element); for odd N the lifted one that the
// spec's `quaternion` kind uses.
Eigen::Quaterniond rotationQuaternion(const Group& group, int i);

}  // namespace masa::sym
