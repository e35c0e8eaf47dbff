// "yaml": a task described by its config instead of code (docs/yaml_task.md). The observation
// comes from named joints, bodies and sensors (yaml_observation.hpp); the reward is a sum of
// locomotion and balance terms (forward velocity towards a heading, alive, upright, heading,
// lateral velocity, action and energy costs); the episode ends on a body's height or tilt; actions
// drive the actuators through their ctrlrange or a PD loop around the pose (yaml_pose.hpp). The
// heading is task state: the symmetry rotates it with the robot, so a walk towards it stays
// symmetric under any group, and a policy can observe it (source: heading).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "common/core/config_error.hpp"
#include "common/symmetry/group_element.hpp"
#include "common/sim/model_lookup.hpp"
#include "common/sim/yaml/yaml_observation.hpp"
#include "common/sim/yaml/yaml_pose.hpp"
#include "common/sim/yaml/yaml_task_config.hpp"
#include "common/sim/yaml/yaml_task.hpp"

namespace masa::task {
namespace {

std::vector<std::pair<std::string, double>> termsWithUnitWeights(const YamlTaskConfig& c) {
  std::vector<std::pair<std::string, double>> terms;
  for (const RewardTermConfig& t : c.reward) terms.emplace_back(t.name, 1.0);
  return terms;
}

// A local axis of a body in the world (a column of its rotation; poses are fresh after a step).
Eigen::Vector3d bodyAxis(const mjData* d, int body, int axis) {
  const double* r = d->xmat + 9 * body;
  return Eigen::Vector3d(r[axis], r[3 + axis], r[6 + axis]);
}

// "" when the measure d . (R e), of a body's local axis e against the world direction d (the
// heading, which the symmetry turns with the robot, or the fixed up axis z), is the same in T_i s as
// in s for every group element; else why not. A robot base turns as g R g^-1 (a mirror: M R M), so
// another of its axes takes e's place unless g^-1 e = e; a carried object turns as g R.
std::string axisMeasureAsymmetry(const sym::Group& g, sym::FreeJointKind kind, int axis, bool against_heading) {
  const Eigen::Vector3d e = Eigen::Vector3d::Unit(axis), z = Eigen::Vector3d::UnitZ();
  for (int i = 1; i < g.order; ++i) {
    const Eigen::Matrix3d gt = sym::spatialMap(g, i).transpose();
    const bool conjugated = kind == sym::FreeJointKind::kRobotBase || sym::isMirror(g, i);
    const bool e_kept = !conjugated || (gt * e - e).norm() < 1e-9;
    const bool e_flipped = conjugated && (gt * e + e).norm() < 1e-9;
    if (against_heading ? e_kept : ((gt * z - z).norm() < 1e-9 && e_kept) || ((gt * z + z).norm() < 1e-9 && e_flipped))
      continue;
    return std::string("the symmetry turns the body so that another of its axes takes the place of its local ") +
           char('x' + axis) + " axis" + (against_heading ? "" : ", or the world's up axis is not kept") +
           ": the measure would not be symmetric; use the body axis along the group's axis";
  }
  return "";
}

class YamlTask final : public Task {
 public:
  YamlTask(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec, EnvParams& p)
      : YamlTask(std::move(model), spec, p, readYamlTaskConfig(p, spec.numAgents())) {}

  std::vector<std::string> progressNames() const override {
    if (walker_ < 0) return {"time_s"};
    return {"time_s", "distance_m", "speed_mps"};
  }
  void progress(double* out) const override {
    const double t = episode().length * controlTimestep();
    out[0] = t;
    if (walker_ < 0) return;
    out[1] = (Eigen::Vector3d(data_->xpos + 3 * rewards_[walker_].free.body) - start_).dot(heading_);
    out[2] = t > 0 ? out[1] / t : 0.0;
  }

 protected:
  // The pose plus uniform noise on each actuated joint's position (kept inside its range) and
  // velocity, noise on every velocity, the robot stood on its support, then the heading. A noise
  // of 0 draws nothing.
  void resetTask(Rng& rng) override {
    const mjModel* m = model();
    const ResetConfig& r = config_.reset;
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (int k = 0; k < actDim(); ++k) {
      const int j = jointOfAction(k);
      targets_[k] = pose_[k];
      if (j < 0) continue;
      double q = pose_[k];
      if (r.joint_noise > 0) q += r.joint_noise * unit(rng);
      if (m->jnt_limited[j]) q = std::clamp(q, m->jnt_range[2 * j], m->jnt_range[2 * j + 1]);
      data_->qpos[m->jnt_qposadr[j]] = q;
      if (r.joint_velocity_noise > 0) data_->qvel[m->jnt_dofadr[j]] = r.joint_velocity_noise * unit(rng);
    }
    if (r.velocity_noise > 0)
      for (int d = 0; d < m->nv; ++d) data_->qvel[d] = r.velocity_noise * unit(rng);
    if (!feet_.empty()) {
      mj_kinematics(m, data_);
      double lowest = 1e9;
      for (int g : feet_) lowest = std::min(lowest, data_->geom_xpos[3 * g + 2] - m->geom_rbound[g]);
      data_->qpos[rest_base_qadr_ + 2] += support_top_ + r.clearance - lowest;
    }
    heading_ = config_.heading.direction;
    if (config_.heading.random_yaw) {
      const double yaw = std::numbers::pi * unit(rng);
      heading_ = Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0);
    }
    if (walker_ >= 0) start_ = Eigen::Vector3d(data_->qpos + rewards_[walker_].free.qadr);
  }

  void applyAction(const double* action) override {
    if (!config_.actuation.pd) return Task::applyAction(action);
    for (int k = 0; k < actDim(); ++k) targets_[k] = pose_[k] + config_.actuation.action_scale * action[k];
  }

  // The PD loop runs every physics substep.
  void beforeSubstep() override {
    if (!config_.actuation.pd) return;
    const mjModel* m = model();
    for (int k = 0; k < actDim(); ++k) {
      const int j = jointOfAction(k);
      const double tau = config_.actuation.kp * kpScale(k) * (targets_[k] - data_->qpos[m->jnt_qposadr[j]]) -
                         config_.actuation.kd * kdScale(k) * data_->qvel[m->jnt_dofadr[j]];
      data_->ctrl[actuatorOfAction(k)] = std::clamp(tau, -torque_limit_[k], torque_limit_[k]);
    }
  }

 public:
  // The PD law as a robot's joint command (masa_deploy); a task driving torques has none.
  bool jointCommand(const double* action, double* position, double* velocity, double* torque_ff, double* kp,
                    double* kd) const override {
    if (!config_.actuation.pd) return false;
    for (int k = 0; k < actDim(); ++k) {
      position[k] = pose_[k] + config_.actuation.action_scale * std::clamp(action[k], -1.0, 1.0);
      velocity[k] = torque_ff[k] = 0.0;
      kp[k] = config_.actuation.kp;
      kd[k] = config_.actuation.kd;
    }
    return true;
  }

 protected:
  void writeObservation(float* out) const override { observation_.write(data_, lastAction(), heading_, out); }

  // MuJoCo computes sensors inside mj_step, before its last substep: refresh them for the final state.
  void afterStep() override {
    if (observation_.usesSensors()) mj_forward(model(), data_);
  }

  void computeRewardTerms(double* raw) const override {
    const Eigen::Vector3d lateral = Eigen::Vector3d::UnitZ().cross(heading_);
    for (std::size_t k = 0; k < rewards_.size(); ++k) {
      const Term& t = rewards_[k];
      const RewardTermConfig& c = config_.reward[k];
      switch (c.type) {
        case RewardType::kAlive: raw[k] = 1.0; break;
        case RewardType::kForwardVelocity: {
          const double v = t.free.linearVelocity(data_).dot(heading_);
          raw[k] = c.has_target ? std::exp(-std::abs(v - c.target)) : v;
          break;
        }
        case RewardType::kHeading: raw[k] = bodyAxis(data_, t.body, c.axis).dot(heading_); break;
        case RewardType::kUpright: {
          const double up = bodyAxis(data_, t.body, c.axis).z();
          raw[k] = c.has_threshold ? (up > c.threshold ? 1.0 : 0.0) : up;
          break;
        }
        case RewardType::kLateralVelocity: raw[k] = std::abs(t.free.linearVelocity(data_).dot(lateral)); break;
        case RewardType::kActionSquared: {
          double a2 = 0.0;
          for (double a : lastAction()) a2 += a * a;
          raw[k] = a2;
          break;
        }
        case RewardType::kEnergy: raw[k] = jointPower(); break;
      }
    }
  }

  bool isTerminated() const override {
    for (std::size_t k = 0; k < ends_.size(); ++k) {
      const TerminationConfig& c = config_.termination[k];
      const End& e = ends_[k];
      if (c.type == TerminationType::kHeight) {
        const double below = e.above >= 0 ? data_->xpos[3 * e.above + 2] : e.above_top;
        if (data_->xpos[3 * e.body + 2] - below < c.min) return true;
      } else if (bodyAxis(data_, e.body, c.axis).z() < c.min) {
        return true;
      }
    }
    return false;
  }

  void transformExtras(int i) override {
    const Eigen::Matrix3d g = sym::spatialMap(spec().group(), i);
    heading_ = g * heading_;
    start_ = g * start_;
  }
  void saveExtras(std::vector<double>& out) const override {
    out.insert(out.end(), {heading_.x(), heading_.y(), heading_.z(), start_.x(), start_.y(), start_.z()});
  }
  void loadExtras(std::span<const double> in) override {
    if (in.size() != 6) throw std::runtime_error(name() + " state: 6 extras (heading, start) expected, got " + std::to_string(in.size()));
    heading_ = Eigen::Vector3d(in[0], in[1], in[2]);
    start_ = Eigen::Vector3d(in[3], in[4], in[5]);
  }

 private:
  struct Term {
    int body = -1;
    FreeBody free;
  };
  struct End {
    int body = -1, above = -1;  // above: a body, else the constant height above_top
    double above_top = 0.0;
  };

  YamlTask(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec, EnvParams& p, YamlTaskConfig c)
      : Task("yaml", std::move(model), spec, p, termsWithUnitWeights(c)),
        config_(std::move(c)),
        pose_(resolvePose(config_, *this)),
        observation_(config_, *this, pose_) {
    const MujocoModel& mm = mujocoModel();
    for (const RewardTermConfig& t : config_.reward) {
      Term term;
      const bool moves = t.type == RewardType::kForwardVelocity || t.type == RewardType::kLateralVelocity;
      if (moves) term.free = findFreeBody(mm, spec, t.body, t.file, t.path + ".body");
      if (!t.body.empty()) term.body = findNamed(mm, mjOBJ_BODY, t.body, t.file, t.path + ".body");
      if (t.type == RewardType::kForwardVelocity && walker_ < 0) walker_ = static_cast<int>(rewards_.size());
      if (t.type == RewardType::kHeading || t.type == RewardType::kUpright)
        checkAxisMeasure(t.body, t.axis, t.type == RewardType::kHeading, t.file, t.path);
      rewards_.push_back(term);
    }
    for (const TerminationConfig& t : config_.termination) {
      End e;
      e.body = findNamed(mm, mjOBJ_BODY, t.body, t.file, t.path + ".body");
      if (!t.above.empty()) e.above = findNamed(mm, mjOBJ_BODY, t.above, t.file, t.path + ".above");
      if (!t.above_geom.empty()) e.above_top = worldGeomTop(mm, t.above_geom, t.file, t.path + ".above_geom");
      if (t.type == TerminationType::kUpright) checkAxisMeasure(t.body, t.axis, false, t.file, t.path);
      ends_.push_back(e);
    }
    resolveActuation();
    resolveRestOn();
  }

  // Bodies moved by a listed free joint are checked here; others (links of a limb) by masa_verify.
  void checkAxisMeasure(const std::string& body, int axis, bool against_heading, const std::string& file,
                        const std::string& path) const {
    const mjModel* m = model();
    const int b = mj_name2id(m, mjOBJ_BODY, body.c_str());
    for (const auto& fj : spec().mujoco().free_joints) {
      const int j = mj_name2id(m, mjOBJ_JOINT, fj.name.c_str());
      if (j < 0 || m->jnt_bodyid[j] != b) continue;
      const std::string why = axisMeasureAsymmetry(spec().group(), fj.kind, axis, against_heading);
      if (!why.empty()) throw ConfigError(file, path + ".axis", "body '" + body + "': " + why);
    }
  }

  // A PD loop needs a joint per action and a symmetric ctrlrange: its torque limit.
  void resolveActuation() {
    targets_ = pose_;
    torque_limit_.assign(actDim(), 0.0);
    if (!config_.actuation.pd) return;
    const mjModel* m = model();
    for (int k = 0; k < actDim(); ++k) {
      const int a = actuatorOfAction(k);
      const double* range = m->actuator_ctrlrange + 2 * a;
      if (jointOfAction(k) < 0 || !m->actuator_ctrllimited[a] || range[0] != -range[1])
        throw ConfigError(config_.actuation.file, "env.actuation",
                          "a PD loop drives each action's joint through an actuator with a symmetric ctrlrange (its "
                          "torque limit); action " + spec().actNames()[k] + "'s does not have one");
      torque_limit_[k] = range[1];
    }
  }

  void resolveRestOn() {
    const ResetConfig& r = config_.reset;
    if (r.support.empty()) return;
    const std::string at = r.path + ".rest_on";
    support_top_ = worldGeomTop(mujocoModel(), r.support, r.file, at + ".support");
    for (const std::string& f : r.feet) feet_.push_back(findNamed(mujocoModel(), mjOBJ_GEOM, f, r.file, at + ".feet"));
    if (!hasRobotBase())
      throw ConfigError(r.file, at, "standing the robot on a support moves its base: the spec's mujoco.free_joints "
                                    "lists no robot_base");
    for (const auto& fj : spec().mujoco().free_joints)
      if (fj.kind == sym::FreeJointKind::kRobotBase)
        rest_base_qadr_ = model()->jnt_qposadr[mj_name2id(model(), mjOBJ_JOINT, fj.name.c_str())];
  }

  YamlTaskConfig config_;
  std::vector<double> pose_;  // per action: its joint's reference position
  YamlObservation observation_;
  std::vector<Term> rewards_;
  std::vector<End> ends_;
  std::vector<double> targets_, torque_limit_;  // PD loop, per action
  std::vector<int> feet_;                       // reset.rest_on: geoms
  double support_top_ = 0.0;
  int rest_base_qadr_ = -1;
  int walker_ = -1;                 // the first forward_velocity term: its body's walk is the progress
  Eigen::Vector3d heading_{1.0, 0.0, 0.0}, start_{0.0, 0.0, 0.0};
};

}  // namespace

// Listed in tasks/tasks.cpp.
std::unique_ptr<Task> makeYamlTask(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec,
                                   EnvParams& params) {
  return std::make_unique<YamlTask>(std::move(model), spec, params);
}

}  // namespace masa::task
