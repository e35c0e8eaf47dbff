#include "common/symmetry/group_element.hpp"

#include <cmath>

namespace masa::sym {

bool isMirror(const Group& group, int i) { return group.type == GroupType::kReflection && (i % 2) != 0; }

Eigen::Quaterniond rotationQuaternion(const Group& group, int i) {
  if (group.type == GroupType::kReflection) return Eigen::Quaterniond::Identity();
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  axis(static_cast<int>(group.axis)) = 1.0;
  const double angle = -2.0 * M_PI * static_cast<double>(i % group.order) / group.order;
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
