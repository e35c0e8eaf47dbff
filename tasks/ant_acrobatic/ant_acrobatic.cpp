// Ant Acrobatic: an ant stands on a free ball and balances a free pole standing in a shallow cup on
// its torso (paper appendix "Ant Acrobatic"). Actions are motor torques; the reward is alive minus
// action and energy costs; the episode ends when the pole tilts or drops or the ant leaves the top
// of the ball. See tasks/ant_acrobatic/README.md for the tables and our choices.
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>

#include "common/core/check.hpp"
#include "common/core/config_error.hpp"
#include "tasks/tasks.hpp"

namespace masa::task {
namespace {

constexpr int kLegs = 4;
constexpr int kJointsPerLeg = 2;  // hip, ankle (the spec's limb action order)
constexpr int kCentralObs = 34;
constexpr int kLimbObs = 6;
constexpr double kPi = 3.14159265358979323846;

class AntAcrobatic final : public Task {
 public:
  AntAcrobatic(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec, EnvParams& p)
      : Task("ant_acrobatic", std::move(model), spec, p, {{"alive", 0.5}, {"action", -0.005}, {"energy", -0.05}}) {
    min_pole_up_ = p.number("min_pole_up", 0.98);
    min_pole_above_torso_ = p.number("min_pole_above_torso", 1.0);
    min_torso_above_ball_ = p.number("min_torso_above_ball", 0.9);
    ankle_init_ = p.number("reset_ankle_deg", 80.0) * kPi / 180.0;
    joint_noise_ = p.number("reset_joint_noise", 0.1);
    vel_noise_ = p.number("reset_velocity_noise", 0.05);
    if (joint_noise_ < 0 || vel_noise_ < 0)
      throw ConfigError("configs", "env.reset_joint_noise", "reset noise scales must be >= 0");

    MASA_CHECK(spec.actCentralDim() == 0 && spec.actLimbDim() == kJointsPerLeg && spec.numAgents() == kLegs &&
                   spec.obsCentralDim() == kCentralObs && spec.obsLimbDim() == kLimbObs,
               "ant_acrobatic needs 4 limbs x (hip, ankle) and 34 + 4 x 6 observations, spec gives "
                   << actDim() << " actions and " << obsDim() << " observations");
    const mjModel* m = model_->get();
    for (int k = 0; k < kLegs * kJointsPerLeg; ++k) {
      const int j = jointOfAction(k);
      MASA_CHECK(j >= 0 && m->jnt_type[j] == mjJNT_HINGE, "action " << k << " must drive a hinge joint");
      qadr_[k] = m->jnt_qposadr[j];
      vadr_[k] = m->jnt_dofadr[j];
      lo_[k] = m->jnt_range[2 * j];
      hi_[k] = m->jnt_range[2 * j + 1];
    }
    bindFree("root", "torso", torso_);
    bindFree("pole_root", "pole", pole_);
    bindFree("ball_root", "ball", ball_);
  }

 // The episode ends when the pole tilts or drops, so its length is the time the pole stayed up.
  std::vector<std::string> progressNames() const override { return {"pole_up_s"}; }
  void progress(double* out) const override { out[0] = episode().length * controlTimestep(); }

 protected:
  // The XML pose (ant on top of the ball, pole upright in the cup) with the ankles bent to
  // reset_ankle_deg, uniform joint noise (kept inside the joint ranges) and uniform velocity noise
  // on every degree of freedom.
  void resetTask(Rng& rng) override {
    const mjModel* m = model_->get();
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (int k = 0; k < kLegs * kJointsPerLeg; ++k) {
      const double base = (k % kJointsPerLeg == 1) ? ankle_init_ : 0.0;
      data_->qpos[qadr_[k]] = std::clamp(base + joint_noise_ * unit(rng), lo_[k], hi_[k]);
    }
    for (int d = 0; d < m->nv; ++d) data_->qvel[d] = vel_noise_ * unit(rng);
  }

  void writeObservation(float* out) const override {
    int o = 0;
    auto put = [&](const double* v, int n) {
      for (int c = 0; c < n; ++c) out[o++] = static_cast<float>(v[c]);
    };
    double w[3];
    // Torso: position, world linear velocity, world angular velocity, quaternion with w >= 0
    // (conjugation keeps w, so this canonical sign is itself equivariant).
    const double* tq = data_->qpos + torso_.qadr;
    put(tq, 3);
    put(data_->qvel + torso_.vadr, 3);
    worldAngVel(torso_, w);
    put(w, 3);
    const double s = tq[3] < 0 ? -1.0 : 1.0;
    for (int c = 3; c < 7; ++c) out[o++] = static_cast<float>(s * tq[c]);
    // Pole: centre, world linear and angular velocity, its long (body z) axis in the world.
    put(data_->qpos + pole_.qadr, 3);
    put(data_->qvel + pole_.vadr, 3);
    worldAngVel(pole_, w);
    put(w, 3);
    double up[3];
    poleUp(up);
    put(up, 3);
    // Ball: centre, world linear and angular velocity.
    put(data_->qpos + ball_.qadr, 3);
    put(data_->qvel + ball_.vadr, 3);
    worldAngVel(ball_, w);
    put(w, 3);
    const std::vector<double>& act = lastAction();
    for (int leg = 0; leg < kLegs; ++leg)
      for (int field = 0; field < 3; ++field)
        for (int slot = 0; slot < kJointsPerLeg; ++slot) {
          const int k = leg * kJointsPerLeg + slot;
          const double v = field == 0 ? data_->qpos[qadr_[k]] : field == 1 ? data_->qvel[vadr_[k]] : act[k];
          out[o++] = static_cast<float>(v);
        }
  }

  void computeRewardTerms(double* raw) const override {
    double a2 = 0.0;
    for (double a : lastAction()) a2 += a * a;
    raw[0] = 1.0;           // alive
    raw[1] = a2;            // action: ||a||^2
    raw[2] = jointPower();  // energy: sum |torque * joint velocity| (W)
  }

  bool isTerminated() const override {
    double up[3];
    poleUp(up);
    const double torso_z = data_->qpos[torso_.qadr + 2];
    return up[2] < min_pole_up_ || data_->qpos[pole_.qadr + 2] - torso_z < min_pole_above_torso_ ||
           torso_z - data_->qpos[ball_.qadr + 2] < min_torso_above_ball_;
  }

 private:
  struct Free {
    int body = -1, qadr = -1, vadr = -1;
  };

  void bindFree(const char* joint, const char* body, Free& f) const {
    const mjModel* m = model_->get();
    const int j = model_->id(mjOBJ_JOINT, joint);
    MASA_CHECK(m->jnt_type[j] == mjJNT_FREE, "joint '" << joint << "' must be a free joint");
    f.body = model_->id(mjOBJ_BODY, body);
    MASA_CHECK(m->jnt_bodyid[j] == f.body, "free joint '" << joint << "' must belong to body '" << body << "'");
    f.qadr = m->jnt_qposadr[j];
    f.vadr = m->jnt_dofadr[j];
  }

  // Everything is computed from qpos/qvel: after mj_step, xmat still holds the orientations of
  // the last substep's start, which a freshly transformed state (mj_forward) would not match.
  // A free joint stores its angular velocity in the body frame; rotate it into the world.
  void worldAngVel(const Free& f, double* w) const {
    mju_rotVecQuat(w, data_->qvel + f.vadr + 3, data_->qpos + f.qadr + 3);
  }
  // The pole's long axis (body z) in the world.
  void poleUp(double* up) const {
    const double ez[3] = {0.0, 0.0, 1.0};
    mju_rotVecQuat(up, ez, data_->qpos + pole_.qadr + 3);
  }

  double min_pole_up_, min_pole_above_torso_, min_torso_above_ball_;
  double ankle_init_, joint_noise_, vel_noise_;
  std::array<int, kLegs * kJointsPerLeg> qadr_{}, vadr_{};
  std::array<double, kLegs * kJointsPerLeg> lo_{}, hi_{};
  Free torso_, pole_, ball_;
};

}  // namespace

// Listed in tasks/tasks.cpp.
std::unique_ptr<Task> makeAntAcrobatic(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec,
                                       EnvParams& params) {
  return std::make_unique<AntAcrobatic>(std::move(model), spec, params);
}

}  // namespace masa::task
