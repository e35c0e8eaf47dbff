// What the humanoid tasks (tightrope, dribbling) share: the 21-actuator humanoid's observation
// blocks in the spec layout, its standing start pose, its energy term, and the optional end of an
// episode on a tilted torso (env.max_tilt_deg).
//
// Every quantity is read from qpos/qvel (never from xpos/xmat, which mj_step leaves one substep
// behind), so an observation after step() equals the same observation after mj_forward: the
// symmetry verifier compares exactly these two.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common/core/check.hpp"
#include "common/sim/task.hpp"

namespace masa::task {

// A frame on the ground in which observations are expressed: origin (x, y) and heading (rad) of
// its x axis about world z. The tightrope uses the world frame; dribbling the current segment's.
struct PlanarFrame {
  double x = 0.0, y = 0.0, heading = 0.0;
  // World (x, y) vector -> frame coordinates (rotation only).
  void rotateIn(const double* v, double* out) const;
};

class HumanoidTask : public Task {
 public:
  static constexpr int kTorsoObs = 11;  // y, z, linear velocity (3), angular velocity (3), roll, pitch, yaw

  // Motor torques (the humanoid is torque-controlled), with the start pose as position targets.
  bool jointCommand(const double* action, double* position, double* velocity, double* torque_ff, double* kp,
                    double* kd) const override {
    return motorJointCommand(action, start_pose_.data(), position, velocity, torque_ff, kp, kd);
  }

 protected:
  // start_hip_x: both hips' adduction angle (rad) of the start pose (invariant joints: the pose
  // stays mirror-symmetric). extra_central_obs: the task's own central entries after the 20
  // humanoid ones (the spec's layout is checked against this).
  HumanoidTask(std::string name, std::shared_ptr<const MujocoModel> model, sym::SymmetrySpec spec, EnvParams& params,
               const std::vector<std::pair<std::string, double>>& terms, double start_hip_x_default,
               int extra_central_obs);

  // Start pose (+ uniform noise of env.reset_noise on hinge angles and all velocities), torso
  // upright at the world origin facing +x. Needs mj_kinematics before the stand* calls.
  void randomizePose(Rng& rng);
  // Moves the root vertically so that the lowest foot touches the ground plane z = 0 / the top of a
  // rope along x (axis at y = 0, height axis_z); returns the torso height.
  double standOnGround();
  double standOnRope(double axis_z, double radius);

  // Central block of both tasks (20 values): torso (kTorsoObs) in `frame`, then the central
  // joints' positions, velocities and last actions.
  void writeHumanoidCentral(const PlanarFrame& frame, float* out) const;
  // The limb blocks (limb 0 = right, limb 1 = left): positions, velocities, last actions.
  void writeLimbs(float* out) const;

  const double* torsoPos() const;     // world, m
  const double* torsoLinVel() const;  // world, m/s
  void torsoRotation(double* mat) const;  // row-major 3x3, torso frame -> world
  double actionSquaredNorm() const;
  // env.max_tilt_deg (the authors' later Isaac Lab tasks: 30): true once the torso's z axis tilts
  // more than that from upright; never with 0, the default (the paper's tasks). Mirror-invariant.
  bool tiltedPastLimit() const;

 private:
  void writeJoints(int first_action, int n, float* out) const;
  // Lowest foot-capsule clearance for a root shifted vertically by dz (needs fresh geom_xpos).
  double ropeClearance(double dz, double axis_z, double radius) const;

  int root_qpos_, root_dof_;
  std::vector<int> foot_geoms_;
  std::vector<int> hip_x_qpos_;
  double reset_noise_, start_hip_x_;
  double min_up_z_ = -2.0;  // tiltedPastLimit below this cosine of the tilt (-2: never)
  std::vector<double> start_pose_;  // the start pose without noise, action order
};

}  // namespace masa::task
