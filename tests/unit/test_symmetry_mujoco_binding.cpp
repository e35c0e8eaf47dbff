// The spec's optional `mujoco` section: actuators in action order and free-joint kinds.
#include <gtest/gtest.h>

#include "common/core/config_error.hpp"
#include "common/symmetry/symmetry_spec.hpp"

namespace masa::sym {
namespace {

const std::string kBase = R"(
name: bound
group: {type: reflection, axis: y}
observation:
  central: [{name: z, kind: polar_z}]
action:
  central: [{name: waist, kind: odd}]
  limb: [{name: shoulder, kind: invariant}, {name: elbow, kind: invariant}]
)";

std::string keyOf(const std::string& mujoco_yaml) {
  try {
    SymmetrySpec::parseString(kBase + mujoco_yaml, "spec.yaml");
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "spec.yaml");
    return e.key();
  }
  return "(no error)";
}

TEST(SymmetryMujocoBinding, ActuatorsComeBackInActionOrder) {
  const auto spec = SymmetrySpec::parseString(kBase + R"(
mujoco:
  actuators:
    central: [w]
    limbs: [[rs, re], [ls, le]]
  free_joints: [{name: root, kind: robot_base}, {name: ball, kind: object}]
)",
                                              "spec.yaml");
  EXPECT_EQ(spec.actuatorsInActionOrder(), (std::vector<std::string>{"w", "rs", "re", "ls", "le"}));
  ASSERT_EQ(spec.mujoco().free_joints.size(), 2u);
  EXPECT_EQ(spec.mujoco().free_joints[0].kind, FreeJointKind::kRobotBase);
  EXPECT_EQ(spec.mujoco().free_joints[1].kind, FreeJointKind::kObject);
}

TEST(SymmetryMujocoBinding, SpecWithoutBindingSaysSoWhenActuatorsAreAsked) {
  const auto spec = SymmetrySpec::parseString(kBase, "spec.yaml");
  EXPECT_FALSE(spec.mujoco().present);
  EXPECT_THROW(spec.actuatorsInActionOrder(), ConfigError);
}

TEST(SymmetryMujocoBinding, MalformedBindingsNameTheKey) {
  EXPECT_EQ(keyOf("mujoco:\n  actuators:\n    central: [w]\n    limbs: [[rs, re], [ls]]\n"),
            "mujoco.actuators.limbs[1]");
  EXPECT_EQ(keyOf("mujoco:\n  actuators:\n    central: [w]\n    limbs: [[rs, re]]\n"), "mujoco.actuators.limbs");
  EXPECT_EQ(keyOf("mujoco:\n  actuators:\n    limbs: [[rs, re], [ls, le]]\n"), "mujoco.actuators.central");
  EXPECT_EQ(keyOf("mujoco:\n  actuators:\n    central: [w, x]\n    limbs: [[rs, re], [ls, le]]\n"),
            "mujoco.actuators.central");
  EXPECT_EQ(keyOf("mujoco:\n  actuators:\n    central: [w]\n    limbs: [[rs, re], [ls, le]]\n  free_joints: "
                  "[{name: b, kind: wheel}]\n"),
            "mujoco.free_joints[0].kind");
  EXPECT_EQ(keyOf("mujoco:\n  actuatorz: {}\n"), "mujoco.actuatorz");
}

}  // namespace
}  // namespace masa::sym
