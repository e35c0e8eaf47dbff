// "yaml": a task described by its config instead of code (docs/yaml_task.md). The observation
// comes from named joints, bodies and sensors (yaml_observation.hpp); the reward is a sum of
// locomotion and balance terms (forward velocity towards a heading, alive, upright, heading,
// lateral velocity, action and energy costs); the episode ends on a body's height or tilt. The
// heading is task state: the symmetry rotates it with the robot, so a walk towards it stays
// symmetric under any group, and a policy can observe it (source: heading).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "common/core/config_error.hpp"
#include "common/symmetry/group_element.hpp"
#include "common/task/free_body.hpp"
#include "common/task/yaml_observation.hpp"
#include "common/task/yaml_task_config.hpp"
#include "tasks/tasks.hpp"

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
  // The reference pose (reset.joint_pos, else the model's qpos0) plus uniform noise on each actuated
  // joint, kept inside its range; uniform noise on every velocity; then the heading.
  void resetTask(Rng& rng) override {
    const mjModel* m = model();
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (int k = 0; k < actDim(); ++k) {
      const int j = jointOfAction(k);
      if (j < 0) continue;
      double q = reset_pose_[k] + config_.reset.joint_noise * unit(rng);
      if (m->jnt_limited[j]) q = std::clamp(q, m->jnt_range[2 * j], m->jnt_range[2 * j + 1]);
      data_->qpos[m->jnt_qposadr[j]] = q;
    }
    for (int d = 0; d < m->nv; ++d) data_->qvel[d] = config_.reset.velocity_noise * unit(rng);
    heading_ = config_.heading.direction;
    if (config_.heading.random_yaw) {
      const double yaw = std::numbers::pi * unit(rng);
      heading_ = Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0);
    }
    if (walker_ >= 0) start_ = Eigen::Vector3d(data_->qpos + rewards_[walker_].free.qadr);
  }

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
        const double below = e.above < 0 ? 0.0 : data_->xpos[3 * e.above + 2];
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
  void copyExtrasFrom(const Task& other) override {
    const auto& o = static_cast<const YamlTask&>(other);
    heading_ = o.heading_;
    start_ = o.start_;
  }

 private:
  struct Term {
    int body = -1;
    FreeBody free;
  };
  struct End {
    int body = -1, above = -1;
  };

  YamlTask(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec, EnvParams& p, YamlTaskConfig c)
      : Task("yaml", std::move(model), spec, p, termsWithUnitWeights(c)),
        config_(std::move(c)),
        observation_(config_, *this) {
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
      if (t.type == TerminationType::kUpright) checkAxisMeasure(t.body, t.axis, false, t.file, t.path);
      ends_.push_back(e);
    }
    resolveResetPose();
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

  // reset.joint_pos names action entries (a limb entry sets that joint in every limb) or joints.
  void resolveResetPose() {
    const mjModel* m = model();
    reset_pose_.assign(actDim(), 0.0);
    for (int k = 0; k < actDim(); ++k)
      if (jointOfAction(k) >= 0) reset_pose_[k] = m->qpos0[m->jnt_qposadr[jointOfAction(k)]];
    const sym::SymmetrySpec& s = spec();
    for (const ResetJointConfig& r : config_.reset.joint_pos) {
      bool found = false;
      auto setEntry = [&](const std::vector<sym::Entry>& block, int first_action) {
        for (const sym::Entry& e : block)
          if (e.name == r.name) {
            for (int c = 0; c < e.size(); ++c) reset_pose_[first_action + e.offset + c] = r.value;
            found = true;
          }
      };
      setEntry(s.actionLayout().central, 0);
      for (int limb = 0; limb < s.numAgents(); ++limb)
        setEntry(s.actionLayout().limb, s.actCentralDim() + limb * s.actLimbDim());
      if (found) continue;
      const int j = mj_name2id(m, mjOBJ_JOINT, r.name.c_str());
      const auto& joints = actionJoints();
      const auto at = std::find(joints.begin(), joints.end(), j);
      if (j < 0 || at == joints.end()) {
        std::string known;
        for (const auto* block : {&s.actionLayout().central, &s.actionLayout().limb})
          for (const sym::Entry& e : *block) known += (known.empty() ? "" : ", ") + e.name;
        throw ConfigError(r.file, r.path,
                          "'" + r.name + "' is neither an action entry of " + s.source() + " (" + known +
                              ") nor an actuated joint of " + mujocoModel().path());
      }
      reset_pose_[at - joints.begin()] = r.value;
    }
  }

  YamlTaskConfig config_;
  YamlObservation observation_;
  std::vector<Term> rewards_;
  std::vector<End> ends_;
  std::vector<double> reset_pose_;  // per action: its joint's reference position
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
