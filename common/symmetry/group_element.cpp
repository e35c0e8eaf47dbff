#include "common/symmetry/group_element.hpp"

#include <cmath>

namespace masa::sym {

bool isMirror(const Group& group, int i) { return group.type == GroupType::kReflection && (i % 2) != 0; }

Eigen::Quaterniond rotationQuaternion(const Group& group, int i) {
  if (group.type == GroupType::kReflection) return Eigen::Quaterniond::Identity();
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  axis(static_cast<int>(group.axis)) = 1.0;
  // Odd N: the lifted angle -2 pi i (N+1)/N, the same rotation but with p^N = +1, so that a
  // carried object's stored quaternion equals what the spec's `quaternion` kind predicts (not its
  // negative). Even N has no such lift; conjugation (robot bases) does not see the sign.
  const int n = group.order, k = i % n;
  const double angle = (n % 2 == 1) ? -2.0 * M_PI * k * (n + 1) / n : -2.0 * M_PI * k / n;
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis));
}

Eigen::Matrix3d spatialMap(const Group& group, int i) {
  if (group.type == GroupType::kReflection) {
    Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
    if (isMirror(group, i)) m(static_cast<int>(group.axis), static_cast<int>(group.axis)) = -1.0;
    return m;
  }
  return rotationQuaternion(group, i).toRotationMatrix();
}

}  // namespace masa::sym
