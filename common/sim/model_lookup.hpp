// Looking up what a YAML task names in its model, with errors that list what the model does have,
// and the bodies moved by a free joint: where their pose and velocity live in qpos / qvel and how
// the spec's symmetry moves them (robot base or carried object).
#pragma once

#include <string>

#include <Eigen/Core>

#include "common/symmetry/symmetry_spec.hpp"
#include "common/sim/mujoco_model.hpp"

namespace masa::task {

// The id of the object of `type` (mjOBJ_BODY, mjOBJ_JOINT, mjOBJ_SENSOR, ...) called `name`; a
// ConfigError at `file`/`path` that lists the model's names of that type when there is none.
int findNamed(const MujocoModel& model, int type, const std::string& name, const std::string& file,
              const std::string& path);

// The height of the top of a geom fixed in the world (a floor, a beam), from the model: a plane's
// z, or the centre plus the half height of an upright box, sphere, cylinder or capsule.
// ConfigError at `file`/`path` for a geom that moves, is tilted, or has another shape.
double worldGeomTop(const MujocoModel& model, const std::string& name, const std::string& file,
                    const std::string& path);

struct FreeBody {
  int body = -1, qadr = -1, vadr = -1;
  sym::FreeJointKind kind = sym::FreeJointKind::kObject;

  // Fresh after mj_kinematics (Task::step refreshes poses): world position and orientation.
  Eigen::Vector3d linearVelocity(const mjData* d) const;        // world frame (MuJoCo's free-joint qvel)
  Eigen::Vector3d angularVelocityBody(const mjData* d) const;   // the body's own frame (qvel)
  Eigen::Vector3d angularVelocityWorld(const mjData* d) const;
  Eigen::Vector3d axisInWorld(const mjData* d, int local_axis) const;  // a column of the body's rotation
};

// The body `name` with its free joint, which the spec's mujoco.free_joints must list (its kind is
// what the symmetry does to it). ConfigError at `file`/`path` otherwise.
FreeBody findFreeBody(const MujocoModel& model, const sym::SymmetrySpec& spec, const std::string& name,
                      const std::string& file, const std::string& path);

}  // namespace masa::task
