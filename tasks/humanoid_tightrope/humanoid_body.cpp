#include "tasks/humanoid_tightrope/humanoid_body.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "common/core/config_error.hpp"

namespace masa::task {

void PlanarFrame::rotateIn(const double* v, double* out) const {
  const double c = std::cos(heading), s = std::sin(heading);
  const double x = c * v[0] + s * v[1];
  out[1] = -s * v[0] + c * v[1];
  out[0] = x;
}

HumanoidTask::HumanoidTask(std::string name, std::shared_ptr<const MujocoModel> model, sym::SymmetrySpec spec,
                           EnvParams& params, const std::vector<std::pair<std::string, double>>& terms,
                           double start_hip_x_default, int extra_central_obs)
    : Task(std::move(name), std::move(model), std::move(spec), params, terms) {
  MASA_CHECK(this->spec().obsCentralDim() == kTorsoObs + 3 * this->spec().actCentralDim() + extra_central_obs &&
                 this->spec().obsLimbDim() == 3 * this->spec().actLimbDim(),
             this->spec().source() << ": the observation layout does not match the humanoid's (torso "
                              << kTorsoObs << ", then position, velocity, last action per actuated joint)");
  const mjModel* m = model_->get();
  const int root = model_->id(mjOBJ_JOINT, "root");
  root_qpos_ = m->jnt_qposadr[root];
  root_dof_ = m->jnt_dofadr[root];
  for (const char* g : {"right_foot_outer", "right_foot_inner", "left_foot_outer", "left_foot_inner"})
    foot_geoms_.push_back(model_->id(mjOBJ_GEOM, g));
  for (const char* j : {"right_hip_x", "left_hip_x"}) hip_x_qpos_.push_back(m->jnt_qposadr[model_->id(mjOBJ_JOINT, j)]);
  reset_noise_ = params.number("reset_noise", 0.01);
  start_hip_x_ = params.number("start_hip_x", start_hip_x_default);
  MASA_CHECK(reset_noise_ >= 0.0, "env.reset_noise must not be negative");
  // No steps spent falling from a lean the humanoid cannot recover (the authors' later versions).
  const double max_tilt_deg = params.number("max_tilt_deg", 0.0);
  if (max_tilt_deg < 0.0 || max_tilt_deg >= 180.0)
    throw ConfigError(params.origin("max_tilt_deg"), "env.max_tilt_deg",
                      "must be in [0, 180) degrees (0: no tilt termination), got " + std::to_string(max_tilt_deg));
  min_up_z_ = max_tilt_deg > 0.0 ? std::cos(max_tilt_deg * M_PI / 180.0) : -2.0;
  for (int k = 0; k < actDim(); ++k) {
    const int q = m->jnt_qposadr[jointOfAction(k)];
    const bool hip_x = std::find(hip_x_qpos_.begin(), hip_x_qpos_.end(), q) != hip_x_qpos_.end();
    start_pose_.push_back(hip_x ? start_hip_x_ : m->qpos0[q]);
  }
}

void HumanoidTask::randomizePose(Rng& rng) {
  const mjModel* m = model_->get();
  std::uniform_real_distribution<double> noise(-reset_noise_, reset_noise_);
  for (int q : hip_x_qpos_) data_->qpos[q] = start_hip_x_;
  for (int k = 0; k < actDim(); ++k) data_->qpos[m->jnt_qposadr[jointOfAction(k)]] += noise(rng);
  for (int v = 0; v < m->nv; ++v) data_->qvel[v] = noise(rng);
  mj_kinematics(m, data_);
}

double HumanoidTask::standOnGround() {
  const mjModel* m = model_->get();
  double lowest = 1e9;
  for (int g : foot_geoms_) {
    const double* c = data_->geom_xpos + 3 * g;
    const double* z_axis_z = data_->geom_xmat + 9 * g + 8;  // z component of the capsule axis
    lowest = std::min(lowest, c[2] - std::abs(*z_axis_z) * m->geom_size[3 * g + 1] - m->geom_size[3 * g]);
  }
  data_->qpos[root_qpos_ + 2] -= lowest;
  return data_->qpos[root_qpos_ + 2];
}

double HumanoidTask::ropeClearance(double dz, double axis_z, double radius) const {
  const mjModel* m = model_->get();
  double clearance = 1e9;
  for (int g : foot_geoms_) {
    const double* c = data_->geom_xpos + 3 * g;
    const double* mat = data_->geom_xmat + 9 * g;
    const double h = m->geom_size[3 * g + 1];
    // The capsule's segment in the y-z plane (the rope axis is the point (0, axis_z) there).
    const double ay = c[1] - h * mat[5], az = c[2] + dz - h * mat[8];
    const double by = c[1] + h * mat[5], bz = c[2] + dz + h * mat[8];
    const double dy = by - ay, dzs = bz - az, len2 = dy * dy + dzs * dzs;
    const double t = len2 > 0 ? std::clamp(((0.0 - ay) * dy + (axis_z - az) * dzs) / len2, 0.0, 1.0) : 0.0;
    const double ey = ay + t * dy, ez = az + t * dzs - axis_z;
    clearance = std::min(clearance, std::sqrt(ey * ey + ez * ez) - radius - m->geom_size[3 * g]);
  }
  return clearance;
}

double HumanoidTask::standOnRope(double axis_z, double radius) {
  // Start with every foot point well above the rope, lower in 2 mm steps until a foot would
  // penetrate, then bisect to touching.
  double hi = 0.0;
  for (int g : foot_geoms_) hi = std::max(hi, axis_z + radius + 0.6 - data_->geom_xpos[3 * g + 2]);
  double lo = hi;
  for (int k = 0; k < 1000 && ropeClearance(lo, axis_z, radius) > 0.0; ++k) lo -= 0.002;
  if (ropeClearance(lo, axis_z, radius) > 0.0)
    throw std::runtime_error(model_->path() + ": the start pose puts no foot over the rope");
  hi = lo + 0.002;
  for (int k = 0; k < 40; ++k) {
    const double mid = 0.5 * (lo + hi);
    (ropeClearance(mid, axis_z, radius) > 0.0 ? hi : lo) = mid;
  }
  data_->qpos[root_qpos_ + 2] += hi;
  return data_->qpos[root_qpos_ + 2];
}

const double* HumanoidTask::torsoPos() const { return data_->qpos + root_qpos_; }
const double* HumanoidTask::torsoLinVel() const { return data_->qvel + root_dof_; }
void HumanoidTask::torsoRotation(double* mat) const { mju_quat2Mat(mat, data_->qpos + root_qpos_ + 3); }

void HumanoidTask::writeHumanoidCentral(const PlanarFrame& frame, float* out) const {
  const double* p = torsoPos();
  const double* v = torsoLinVel();
  double r[9];
  torsoRotation(r);
  const double rel[2] = {p[0] - frame.x, p[1] - frame.y};
  double loc[2];
  frame.rotateIn(rel, loc);
  out[0] = static_cast<float>(loc[1]);  // lateral offset from the frame's x axis
  out[1] = static_cast<float>(p[2]);
  frame.rotateIn(v, loc);
  out[2] = static_cast<float>(loc[0]);
  out[3] = static_cast<float>(loc[1]);
  out[4] = static_cast<float>(v[2]);
  // The free joint's angular velocity is in the torso frame: rotate it to the world, then in.
  double w[3];
  mju_rotVecMat(w, data_->qvel + root_dof_ + 3, r);
  frame.rotateIn(w, loc);
  out[5] = static_cast<float>(loc[0]);
  out[6] = static_cast<float>(loc[1]);
  out[7] = static_cast<float>(w[2]);
  // ZYX Euler angles of the torso relative to the frame: R_rel = Rz(-heading) R.
  const double c = std::cos(frame.heading), s = std::sin(frame.heading);
  const double r00 = c * r[0] + s * r[3], r10 = -s * r[0] + c * r[3];
  out[8] = static_cast<float>(std::atan2(r[7], r[8]));
  out[9] = static_cast<float>(std::asin(std::clamp(-r[6], -1.0, 1.0)));
  out[10] = static_cast<float>(std::atan2(r10, r00));
  writeJoints(0, spec().actCentralDim(), out + kTorsoObs);
}

void HumanoidTask::writeLimbs(float* out) const {
  const int nc = spec().actCentralDim(), nl = spec().actLimbDim();
  for (int l = 0; l < spec().numAgents(); ++l) writeJoints(nc + l * nl, nl, out + 3 * nl * l);
}

void HumanoidTask::writeJoints(int first_action, int n, float* out) const {
  const mjModel* m = model_->get();
  for (int k = 0; k < n; ++k) {
    const int j = jointOfAction(first_action + k);
    out[k] = static_cast<float>(data_->qpos[m->jnt_qposadr[j]]);
    out[n + k] = static_cast<float>(data_->qvel[m->jnt_dofadr[j]]);
    out[2 * n + k] = static_cast<float>(lastAction()[first_action + k]);
  }
}

double HumanoidTask::actionSquaredNorm() const {
  double s = 0.0;
  for (double a : lastAction()) s += a * a;
  return s;
}

bool HumanoidTask::tiltedPastLimit() const {
  if (min_up_z_ < -1.0) return false;  // off (the paper's tasks): no rotation to compute each step
  double r[9];
  torsoRotation(r);
  return r[8] < min_up_z_;  // the torso's z axis' world z: the cosine of its tilt
}

}  // namespace masa::task
