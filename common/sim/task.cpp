#include "common/sim/task.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/core/check.hpp"
#include "common/core/config_error.hpp"
#include "common/sim/episode_pushes.hpp"
#include "common/symmetry/group_element.hpp"

namespace masa::task {

Task::Task(std::string name, std::shared_ptr<const MujocoModel> model, sym::SymmetrySpec spec, EnvParams& params,
           const std::vector<std::pair<std::string, double>>& terms_with_default_weights)
    : model_(std::move(model)),
      name_(std::move(name)),
      spec_(std::move(spec)),
      obs_dim_(spec_.obsDim()),
      act_dim_(spec_.actDim()) {
  frame_skip_ = params.integer("frame_skip", 5, 1);
  max_episode_steps_ = params.integer("max_episode_steps", 1000, 1);
  termination_reward_ = params.number("termination_reward", -1.0);
  energy_velocity_scale_ = params.number("energy_velocity_scale", 0.2);
  energy_effort_weighting_ = params.flag("energy_effort_weighting", false);
  for (const auto& [term, w] : terms_with_default_weights) {
    term_names_.push_back(term);
    weights_.push_back(params.weight(term, w));
  }
  term_names_.push_back("termination");
  terms_.assign(term_names_.size(), 0.0);
  raw_terms_.assign(term_names_.size(), 0.0);
  data_ = mj_makeData(model_->get());
  bindActuators();
  // IsaacGymEnvs' Humanoid weighs each joint's electricity cost by its motor's share of the
  // strongest motor (gear / max gear); its Ant does not.
  effort_ratio_.assign(actDim(), 1.0);
  if (energy_effort_weighting_) {
    const mjModel* m = model_->get();
    double max_gear = 0.0;
    for (int k = 0; k < actDim(); ++k) max_gear = std::max(max_gear, std::abs(m->actuator_gear[6 * action_actuator_[k]]));
    for (int k = 0; k < actDim(); ++k)
      effort_ratio_[k] = max_gear > 0 ? std::abs(m->actuator_gear[6 * action_actuator_[k]]) / max_gear : 1.0;
  }
  for (const auto& fj : spec_.mujoco().free_joints) {
    if (fj.kind != sym::FreeJointKind::kRobotBase) continue;
    const int j = model_->id(mjOBJ_JOINT, fj.name);
    if (model_->get()->jnt_type[j] != mjJNT_FREE) continue;  // reported by the verifier
    base_qadr_ = model_->get()->jnt_qposadr[j];
    base_vadr_ = model_->get()->jnt_dofadr[j];
  }
  last_action_.assign(actDim(), 0.0);
  action_scratch_.assign(actDim(), 0.0);
  qpos_scratch_.assign(model_->get()->nq, 0.0);
  qvel_scratch_.assign(model_->get()->nv, 0.0);
  ctrl_scratch_.assign(model_->get()->nu, 0.0);
  episode_.term_sums.assign(term_names_.size(), 0.0);
  const RandomizationConfig randomization = RandomizationConfig::read(params);
  if (randomization.enabled) {
    // Its own copy of the model, written every episode; the derived data is remade for it.
    auto own = model_->clone();
    mjModel* m = own->mutableModel();
    model_ = std::move(own);
    mj_deleteData(data_);
    data_ = mj_makeData(model_->get());
    randomization_ = std::make_unique<PhysicsRandomization>(randomization, m, spec_, action_joint_, action_actuator_);
    if (randomization.push_velocity > 0.0 && base_vadr_ < 0)
      throw ConfigError(params.origin("randomization.push_velocity"), "env.randomization.push_velocity",
                        "pushes move the robot base, and " + name_ + "'s spec names no robot-base free joint");
  }
}

Task::~Task() { mj_deleteData(data_); }

double Task::termWeight(const std::string& term) const {
  for (std::size_t k = 0; k < weights_.size(); ++k)
    if (term_names_[k] == term) return weights_[k];
  MASA_CHECK(false, name_ << " has no reward term '" << term << "'");
  return 0.0;
}

namespace {

// The actuator a spec names: an actuator of that name, else the one actuator driving the joint of
// that name (models whose actuators carry no names).
int boundActuator(const MujocoModel& model, const std::string& spec_source, const std::string& name) {
  const mjModel* m = model.get();
  const int a = mj_name2id(m, mjOBJ_ACTUATOR, name.c_str());
  if (a >= 0) return a;
  const int j = mj_name2id(m, mjOBJ_JOINT, name.c_str());
  if (j < 0)
    throw std::runtime_error(model.path() + ": no actuator or joint named '" + name + "' (bound in " + spec_source + ")");
  std::vector<int> driving;
  for (int k = 0; k < m->nu; ++k)
    if (m->actuator_trntype[k] == mjTRN_JOINT && m->actuator_trnid[2 * k] == j) driving.push_back(k);
  if (driving.size() != 1)
    throw std::runtime_error(model.path() + ": joint '" + name + "' (bound in " + spec_source + ") is driven by " +
                             std::to_string(driving.size()) + " actuators; bind an actuator by its name");
  return driving[0];
}

}  // namespace

void Task::bindActuators() {
  const mjModel* m = model_->get();
  const std::vector<std::string> names = spec_.actuatorsInActionOrder();
  MASA_CHECK(static_cast<int>(names.size()) == actDim(), "spec binds " << names.size() << " actuators to " << actDim()
                                                                       << " actions");
  for (const std::string& n : names) {
    const int a = boundActuator(*model_, spec_.source(), n);
    if (std::find(action_actuator_.begin(), action_actuator_.end(), a) != action_actuator_.end())
      throw std::runtime_error(spec_.source() + ": actuator '" + n + "' is bound to two actions");
    action_actuator_.push_back(a);
    action_joint_.push_back(m->actuator_trntype[a] == mjTRN_JOINT ? m->actuator_trnid[2 * a] : -1);
  }
}

double Task::controlTimestep() const { return frame_skip_ * model_->get()->opt.timestep; }

void Task::reset(Rng& rng) {
  if (randomization_) {
    randomization_->drawEpisode(rng);
    noise_seed_ = static_cast<double>(rng() >> 11);  // exact in a double: saved with the state
    commanded_.assign(static_cast<std::size_t>(randomization_->latencySteps()) + 2, std::vector<double>(actDim(), 0.0));
    randomization_->summarize(episode_.physics);
  }
  mj_resetData(model_->get(), data_);
  std::fill(last_action_.begin(), last_action_.end(), 0.0);
  resetTask(rng);
  mj_forward(model_->get(), data_);
  episode_.ret = 0.0;
  episode_.length = 0;
  std::fill(episode_.term_sums.begin(), episode_.term_sums.end(), 0.0);
  episode_.has_success = hasSuccessMeasure();
  episode_.success = false;
  episode_.terminated = episode_.truncated = false;
}

void Task::observe(float* out) const {
  writeObservation(out);
  if (randomization_ && randomization_->perturbsObservations()) {
    // The step's noise, a function of the episode's seed and the step: the same state observes
    // the same, also in a copy or a resumed actor.
    Rng noise(static_cast<uint64_t>(noise_seed_) ^ (0x9E3779B97F4A7C15ULL * static_cast<uint64_t>(episode_.length + 1)));
    randomization_->perturbObservation(out, obsDim(), noise);
  }
}

void Task::setMeasuredState(const double* joint_pos, const double* joint_vel, const double* base_pose7,
                            const double* base_vel6, const double* last_action) {
  const mjModel* m = model_->get();
  for (int k = 0; k < actDim(); ++k) {
    const int j = action_joint_[k];
    MASA_CHECK(j >= 0, "action " << k << " drives no joint: no measured state for it");
    data_->qpos[m->jnt_qposadr[j]] = joint_pos[k];
    data_->qvel[m->jnt_dofadr[j]] = joint_vel[k];
    last_action_[k] = last_action[k];
  }
  if (base_qadr_ >= 0 && base_pose7 != nullptr) std::copy(base_pose7, base_pose7 + 7, data_->qpos + base_qadr_);
  if (base_vadr_ >= 0 && base_vel6 != nullptr) std::copy(base_vel6, base_vel6 + 6, data_->qvel + base_vadr_);
  mj_kinematics(m, data_);
  mj_comPos(m, data_);
}

std::string Task::measuredStateGap() const {
  const mjModel* m = model_->get();
  std::vector<char> measured(m->njnt, 0);
  for (int k = 0; k < actDim(); ++k)
    if (action_joint_[k] >= 0) measured[action_joint_[k]] = 1;
  for (int j = 0; j < m->njnt; ++j) {
    if (measured[j] || (m->jnt_qposadr[j] == base_qadr_ && base_qadr_ >= 0)) continue;
    const char* n = mj_id2name(m, mjOBJ_JOINT, j);
    return "joint '" + std::string(n ? n : "?") + "' is neither driven by an action nor the robot base";
  }
  for (int k = 0; k < actDim(); ++k)
    if (action_joint_[k] < 0) return "action " + std::to_string(k) + " drives no joint";
  return "";
}

void Task::applyAction(const double* action) {
  const mjModel* m = model_->get();
  for (int k = 0; k < actDim(); ++k) {
    const int a = action_actuator_[k];
    if (m->actuator_ctrllimited[a]) {
      const double lo = m->actuator_ctrlrange[2 * a], hi = m->actuator_ctrlrange[2 * a + 1];
      data_->ctrl[a] = 0.5 * (lo + hi) + 0.5 * (hi - lo) * action[k];
    } else {
      data_->ctrl[a] = action[k];
    }
  }
}

StepOutcome Task::step(std::span<const float> action) {
  if (static_cast<int>(action.size()) != actDim())
    throw std::invalid_argument("task " + name_ + ": action has " + std::to_string(action.size()) +
                                " values, expected " + std::to_string(actDim()));
  return step(action.data());
}

void Task::advancePhysics(const float* action) {
  const mjModel* m = model_->get();
  setControls(action);
  if (randomization_ && (randomization_->latencySteps() > 0 || randomization_->latencyFraction() > 0.0)) {
    // The latency: the action of latencySteps() steps ago drives this step, and the one before
    // it the first substeps of the fraction.
    std::rotate(commanded_.begin(), commanded_.begin() + 1, commanded_.end());  // no allocation per step
    std::copy(action_scratch_.begin(), action_scratch_.end(), commanded_.back().begin());
    // commanded_ holds latencySteps() + 2 actions, newest last (zeros before the episode's first).
    const int late = static_cast<int>(std::lround(randomization_->latencyFraction() * frame_skip_));
    const std::vector<double>& delayed = commanded_[1];
    const std::vector<double>& older = commanded_[0];
    for (int s = 0; s < frame_skip_; ++s) {
      applyAction(s < late ? older.data() : delayed.data());
      beforeSubstep();
      mj_step(m, data_);
    }
    pushIfDue();
    return;
  }
  for (int s = 0; s < frame_skip_; ++s) {
    beforeSubstep();
    mj_step(m, data_);
  }
  if (randomization_) pushIfDue();
}

void Task::pushIfDue() {
  const RandomizationConfig& c = randomization_->config();
  Push push;
  if (!pushAtStep(c.push_velocity, c.push_interval_s, controlTimestep(), static_cast<uint64_t>(noise_seed_),
                  episode_.length, &push))
    return;
  data_->qvel[base_vadr_] += push.dvx;
  data_->qvel[base_vadr_ + 1] += push.dvy;
}

void Task::setControls(const float* action) {
  for (int k = 0; k < actDim(); ++k) {
    const double a = static_cast<double>(action[k]);
    // NaN actions become 0: a policy bug must not poison the simulator state.
    action_scratch_[k] = std::isfinite(a) ? std::clamp(a, -1.0, 1.0) : 0.0;
  }
  std::copy(action_scratch_.begin(), action_scratch_.end(), last_action_.begin());
  applyAction(action_scratch_.data());
}

void Task::actuate(const float* action) {
  setControls(action);
  beforeSubstep();
}

StepOutcome Task::step(const float* action) {
  const mjModel* m = model_->get();
  const int bad_before = data_->warning[mjWARN_BADQACC].number;
  advancePhysics(action);
  // mj_step leaves body poses at the start of its last substep: observations, rewards and
  // terminations must see the state the step ended in (the symmetry verifier compares exactly that).
  mj_kinematics(m, data_);
  mj_comPos(m, data_);
  afterStep();
  // MuJoCo resets the state itself after a divergence; such a step ends the episode.
  const bool diverged = data_->warning[mjWARN_BADQACC].number != bad_before;

  StepOutcome out;
  out.terminated = diverged || isTerminated();
  const int nterms = static_cast<int>(term_names_.size());
  if (out.terminated) {
    std::fill(terms_.begin(), terms_.end(), 0.0);
    terms_[nterms - 1] = termination_reward_;
    out.reward = termination_reward_;
  } else {
    computeRewardTerms(raw_terms_.data());
    out.reward = 0.0;
    for (int k = 0; k < nterms - 1; ++k) {
      terms_[k] = weights_[k] * raw_terms_[k];
      out.reward += terms_[k];
    }
    terms_[nterms - 1] = 0.0;
  }
  ++episode_.length;
  out.truncated = !out.terminated && episode_.length >= max_episode_steps_;
  episode_.ret += out.reward;
  for (int k = 0; k < nterms; ++k) episode_.term_sums[k] += terms_[k];
  episode_.terminated = out.terminated;
  episode_.truncated = out.truncated;
  if (episode_.has_success) episode_.success = isSuccess();
  return out;
}

bool Task::motorJointCommand(const double* action, const double* pose, double* position, double* velocity,
                             double* torque_ff, double* kp, double* kd) const {
  const mjModel* m = model_->get();
  for (int k = 0; k < actDim(); ++k) {
    const int a = action_actuator_[k];
    const bool plain_motor = m->actuator_trntype[a] == mjTRN_JOINT && m->actuator_dyntype[a] == mjDYN_NONE &&
                             m->actuator_gaintype[a] == mjGAIN_FIXED && m->actuator_biastype[a] == mjBIAS_NONE;
    if (!plain_motor || action_joint_[k] < 0) return false;
    const double u = std::clamp(action[k], -1.0, 1.0);
    double ctrl = u;  // as applyAction: [-1, 1] onto the ctrlrange
    if (m->actuator_ctrllimited[a]) {
      const double lo = m->actuator_ctrlrange[2 * a], hi = m->actuator_ctrlrange[2 * a + 1];
      ctrl = 0.5 * (lo + hi) + 0.5 * (hi - lo) * u;
    }
    torque_ff[k] = m->actuator_gear[6 * a] * m->actuator_gainprm[mjNGAIN * a] * ctrl;
    position[k] = pose[k];
    velocity[k] = kp[k] = kd[k] = 0.0;
  }
  return true;
}

double Task::jointPower() const {
  const mjModel* m = model_->get();
  double p = 0.0;
  for (int k = 0; k < actDim(); ++k) {
    const int j = action_joint_[k];
    if (j >= 0) p += std::abs(last_action_[k] * data_->qvel[m->jnt_dofadr[j]]) * effort_ratio_[k];
  }
  return p * energy_velocity_scale_;
}

void freeJointVelocityBlocks(const sym::Group& group, int i, sym::FreeJointKind kind, Eigen::Matrix3d& linear,
                             Eigen::Matrix3d& angular) {
  const Eigen::Matrix3d g = sym::spatialMap(group, i);
  linear = g;
  // Angular velocity of a free joint is in the body frame: see task.hpp and docs.
  if (sym::isMirror(group, i))
    angular = -g;
  else if (kind == sym::FreeJointKind::kRobotBase)
    angular = g;
  else
    angular = Eigen::Matrix3d::Identity();  // a carried object: its body-frame angular velocity is unchanged
}

void transformFreeJoint(const sym::Group& group, int i, sym::FreeJointKind kind, double* qp, double* qv, double* qw) {
  const Eigen::Matrix3d g = sym::spatialMap(group, i);
  Eigen::Matrix3d lin_map, ang_map;
  freeJointVelocityBlocks(group, i, kind, lin_map, ang_map);
  Eigen::Map<Eigen::Vector3d> pos(qp), lin(qv), ang(qv + 3), wlin(qw), wang(qw + 3);
  pos = g * Eigen::Vector3d(pos);
  lin = lin_map * Eigen::Vector3d(lin);
  wlin = lin_map * Eigen::Vector3d(wlin);
  ang = ang_map * Eigen::Vector3d(ang);
  wang = ang_map * Eigen::Vector3d(wang);
  Eigen::Quaterniond q(qp[3], qp[4], qp[5], qp[6]);
  if (sym::isMirror(group, i)) {
    const Eigen::Vector3d v = -(g * q.vec());
    q = Eigen::Quaterniond(q.w(), v.x(), v.y(), v.z());
  } else {
    const Eigen::Quaterniond pq = sym::rotationQuaternion(group, i);
    q = kind == sym::FreeJointKind::kRobotBase ? pq * q * pq.conjugate() : pq * q;
  }
  qp[3] = q.w();
  qp[4] = q.x();
  qp[5] = q.y();
  qp[6] = q.z();
}

Eigen::MatrixXd Task::velocityMap(int i) const {
  const mjModel* m = model_->get();
  const sym::SparseMap& t = spec_.actTransform(i);
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(m->nv, m->nv);
  for (int r = 0; r < t.rows(); ++r) {
    const int begin = t.rowStart()[r];
    const int jr = action_joint_[r], jc = action_joint_[t.colIndex()[begin]];
    if (jr >= 0 && jc >= 0) p(m->jnt_dofadr[jr], m->jnt_dofadr[jc]) = t.values()[begin];
  }
  for (const auto& fj : spec_.mujoco().free_joints) {
    const int d = m->jnt_dofadr[model_->id(mjOBJ_JOINT, fj.name)];
    Eigen::Matrix3d lin, ang;
    freeJointVelocityBlocks(spec_.group(), i, fj.kind, lin, ang);
    p.block<3, 3>(d, d) = lin;
    p.block<3, 3>(d + 3, d + 3) = ang;
  }
  return p;
}

// Hinge and slide joints follow their actuator's action entry (a signed permutation); free joints
// follow their kind; any other joint makes the state transform undefined and is reported by name.
void Task::transformJoints(int i) {
  const mjModel* m = model_->get();
  const sym::SparseMap& t = spec_.actTransform(i);
  std::vector<char> covered(m->njnt, 0);
  std::copy(data_->qpos, data_->qpos + m->nq, qpos_scratch_.begin());
  std::copy(data_->qvel, data_->qvel + m->nv, qvel_scratch_.begin());
  std::copy(data_->ctrl, data_->ctrl + m->nu, ctrl_scratch_.begin());
  std::vector<double> warm(data_->qacc_warmstart, data_->qacc_warmstart + m->nv);

  for (int r = 0; r < t.rows(); ++r) {
    const int begin = t.rowStart()[r], end = t.rowStart()[r + 1];
    if (end - begin != 1 || std::abs(std::abs(t.values()[begin]) - 1.0) > 1e-12)
      throw std::runtime_error(spec_.source() + ": action '" + spec_.actNames()[r] +
                               "' is not a signed permutation of actions, so its joint cannot be mapped");
    const int c = t.colIndex()[begin];
    const double s = t.values()[begin];
    const int jr = action_joint_[r], jc = action_joint_[c];
    if (jr < 0 || jc < 0) throw std::runtime_error(spec_.source() + ": action '" + spec_.actNames()[r] + "' drives no joint");
    if (m->jnt_type[jr] != mjJNT_HINGE && m->jnt_type[jr] != mjJNT_SLIDE)
      throw std::runtime_error(model_->path() + ": actuated joint '" + std::string(mj_id2name(m, mjOBJ_JOINT, jr)) +
                               "' is not a hinge or slide joint");
    data_->qpos[m->jnt_qposadr[jr]] = s * qpos_scratch_[m->jnt_qposadr[jc]];
    data_->qvel[m->jnt_dofadr[jr]] = s * qvel_scratch_[m->jnt_dofadr[jc]];
    data_->qacc_warmstart[m->jnt_dofadr[jr]] = s * warm[m->jnt_dofadr[jc]];
    data_->ctrl[action_actuator_[r]] = s * ctrl_scratch_[action_actuator_[c]];
    covered[jr] = 1;
  }

  for (const auto& fj : spec_.mujoco().free_joints) {
    const int j = model_->id(mjOBJ_JOINT, fj.name);
    if (m->jnt_type[j] != mjJNT_FREE)
      throw std::runtime_error(model_->path() + ": joint '" + fj.name + "' is listed as a free joint but is not one");
    covered[j] = 1;
    transformFreeJoint(spec_.group(), i, fj.kind, data_->qpos + m->jnt_qposadr[j], data_->qvel + m->jnt_dofadr[j],
                       data_->qacc_warmstart + m->jnt_dofadr[j]);
  }
  for (int j = 0; j < m->njnt; ++j)
    if (!covered[j])
      throw std::runtime_error(spec_.source() + ": joint '" + std::string(mj_id2name(m, mjOBJ_JOINT, j)) +
                               "' is neither driven by a bound actuator nor listed in mujoco.free_joints");
}

void Task::applySymmetry(int i) {
  MASA_CHECK(i >= 0 && i < spec_.numAgents(), "group element " << i << " out of range");
  if (i == 0) return;
  transformJoints(i);
  const sym::SparseMap& t = spec_.actTransform(i);
  Eigen::Map<const Eigen::VectorXd> a(last_action_.data(), actDim());
  Eigen::VectorXd ta(actDim());
  t.apply<double>(a, ta);
  std::copy(ta.data(), ta.data() + actDim(), last_action_.begin());
  for (auto& c : commanded_) {  // the delayed actions are actions too
    Eigen::Map<Eigen::VectorXd> ca(c.data(), actDim());
    t.apply<double>(Eigen::VectorXd(ca), ta);
    ca = ta;
  }
  transformExtras(i);
  forwardKeepingState();
}

void Task::forwardKeepingState() {
  const mjModel* m = model_->get();
  std::copy(data_->qpos, data_->qpos + m->nq, qpos_scratch_.begin());
  std::copy(data_->qacc_warmstart, data_->qacc_warmstart + m->nv, qvel_scratch_.begin());
  mj_forward(m, data_);
  std::copy(qpos_scratch_.begin(), qpos_scratch_.begin() + m->nq, data_->qpos);
  std::copy(qvel_scratch_.begin(), qvel_scratch_.begin() + m->nv, data_->qacc_warmstart);
}

}  // namespace masa::task
