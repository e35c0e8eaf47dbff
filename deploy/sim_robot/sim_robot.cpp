#include "deploy/sim_robot/sim_robot.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace masa::deploy {

SimRobot::SimRobot(task::Task& task, const sym::SymmetrySpec& spec)
    : task_(task), model_(task.model()), data_(task.data()), n_(task.actDim()) {
  qpos_adr_.resize(n_);
  qvel_adr_.resize(n_);
  actuator_.resize(n_);
  driver_gear_.resize(n_);
  for (int k = 0; k < n_; ++k) {
    const int j = task_.jointOfAction(k);
    if (j < 0) throw std::runtime_error("action " + std::to_string(k) + " drives no joint");
    qpos_adr_[k] = model_->jnt_qposadr[j];
    qvel_adr_[k] = model_->jnt_dofadr[j];
    actuator_[k] = task_.actuatorOfAction(k);
    // The motor driver knows the nominal gear: a perturbed (weaker or stronger) motor gives another torque.
    const task::PhysicsRandomization* perturbation = task_.randomization();
    driver_gear_[k] = perturbation ? perturbation->nominalGear(actuator_[k]) : model_->actuator_gear[6 * actuator_[k]];
  }
  for (const auto& fj : spec.mujoco().free_joints)
    if (fj.kind == sym::FreeJointKind::kRobotBase) {
      const int j = mj_name2id(model_, mjOBJ_JOINT, fj.name.c_str());
      base_qpos_ = model_->jnt_qposadr[j];
      base_qvel_ = model_->jnt_dofadr[j];
    }
}

void SimRobot::fillState(masa::lcmt_robot_state& st, const StateFaults& faults, double sim_t) const {
  const mjModel* m = model_;
  const mjData* d = data_;
  st.num_joints = n_;
  st.joint_position.resize(n_);
  st.joint_velocity.resize(n_);
  st.joint_torque.resize(n_);
  st.has_base = base_qpos_ >= 0;
  const bool nan = faults.nan_after_s >= 0 && sim_t >= faults.nan_after_s;
  for (int k = 0; k < n_; ++k) {
    st.joint_position[k] = nan ? std::numeric_limits<double>::quiet_NaN() : d->qpos[qpos_adr_[k]];
    st.joint_velocity[k] = d->qvel[qvel_adr_[k]];
    st.joint_torque[k] = d->actuator_force[actuator_[k]] * m->actuator_gear[6 * actuator_[k]];
  }
  if (base_qpos_ < 0) return;
  const double* q = d->qpos + base_qpos_;
  const double* v = d->qvel + base_qvel_;
  st.base_x = q[0], st.base_y = q[1], st.base_z = q[2];
  st.base_qw = q[3], st.base_qx = q[4], st.base_qy = q[5], st.base_qz = q[6];
  if (faults.tilt_after_s >= 0 && sim_t >= faults.tilt_after_s) {  // q * (rotation about the body x by tilt_rad)
    const double tilt[4] = {std::cos(faults.tilt_rad / 2), std::sin(faults.tilt_rad / 2), 0, 0};
    double out[4];
    mju_mulQuat(out, q + 3, tilt);
    st.base_qw = out[0], st.base_qx = out[1], st.base_qy = out[2], st.base_qz = out[3];
  }
  st.base_vx = v[0], st.base_vy = v[1], st.base_vz = v[2];
  st.base_wx = v[3], st.base_wy = v[4], st.base_wz = v[5];
}

void SimRobot::step(const masa::lcmt_robot_command& cmd) {
  const mjModel* m = model_;
  mjData* d = data_;
  for (int k = 0; k < n_; ++k) {
    const int a = actuator_[k];
    const double tau = cmd.kp[k] * (cmd.position[k] - d->qpos[qpos_adr_[k]]) +
                       cmd.kd[k] * (cmd.velocity[k] - d->qvel[qvel_adr_[k]]) + cmd.torque_ff[k];
    double u = tau / driver_gear_[k];
    if (m->actuator_ctrllimited[a]) u = std::clamp(u, m->actuator_ctrlrange[2 * a], m->actuator_ctrlrange[2 * a + 1]);
    d->ctrl[a] = std::isfinite(u) ? u : 0.0;
  }
  mj_step(m, d);
}

void SimRobot::updateKinematics() { mj_kinematics(model_, data_); }

std::vector<double> SimRobot::jointAngles() const {
  std::vector<double> q(n_);
  for (int k = 0; k < n_; ++k) q[k] = data_->qpos[qpos_adr_[k]];
  return q;
}

}  // namespace masa::deploy
