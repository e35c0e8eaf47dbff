#include "deploy/runner/policy_runner.hpp"
#include "tasks/tasks.hpp"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace masa::deploy {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool allFinite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

int64_t wallMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

const char* modeName(Mode m) {
  switch (m) {
    case Mode::kCalibrating: return "calibrating";
    case Mode::kPolicy: return "policy";
    case Mode::kDamping: return "damping";
    case Mode::kHold: return "hold";
    case Mode::kEmergencyStop: return "emergency stop";
  }
  return "?";
}

PolicyRunner::PolicyRunner(policy::LoadedPolicy& policy, const DeployConfig& config, int64_t runner_id)
    : cfg_(config), runner_id_(runner_id), model_(model::InferencePolicy<float>::of(*policy.model)) {
  factory_ = std::make_unique<task::TaskFactory>(task::taskCatalog(), policy.config.task, policy.spec, policy.config.env,
                                                 policy.config.origin, policy.source);
  task_ = factory_->create();
  const std::string gap = task_->measuredStateGap();
  if (!gap.empty())
    throw std::runtime_error("task " + task_->name() + " cannot run on a robot's state alone: " + gap);
  n_ = task_->actDim();
  if (model_->obsDim() != task_->obsDim() || model_->actDim() != n_)
    throw std::runtime_error("the policy's obs/act dims differ from task " + task_->name() + "'s");
  const auto sized = [this](double v) { return std::vector<double>(n_, v); };
  target_ = prev_target_ = vel_ = tau_ = kp_ = kd_ = sized(0.0);
  nominal_ = nominal_kp_ = nominal_kd_ = sized(0.0);
  action_ = last_action_ = hold_pose_ = q_ = qd_ = sized(0.0);
  lower_ = sized(-kInf);
  upper_ = sized(kInf);
  torque_limit_ = sized(kInf);
  std::vector<double> zero = sized(0.0), v = sized(0.0), t = sized(0.0);
  if (!task_->jointCommand(zero.data(), nominal_.data(), v.data(), t.data(), nominal_kp_.data(), nominal_kd_.data()))
    throw std::runtime_error("task " + task_->name() +
                             "'s actuation is not a per-joint PD law (Task::jointCommand): masa_deploy cannot run it");

  const mjModel* m = task_->model();
  for (int k = 0; k < n_; ++k) {
    const int j = task_->jointOfAction(k), a = task_->actuatorOfAction(k);
    if (m->jnt_limited[j]) {
      lower_[k] = m->jnt_range[2 * j] + cfg_.position_margin;
      upper_[k] = m->jnt_range[2 * j + 1] - cfg_.position_margin;
      if (lower_[k] > upper_[k])
        throw std::runtime_error("limits.position_margin leaves no range for joint " + std::to_string(k));
    }
    if (m->actuator_ctrllimited[a])
      torque_limit_[k] = std::abs(m->actuator_gear[6 * a]) *
                         std::max(std::abs(m->actuator_ctrlrange[2 * a]), std::abs(m->actuator_ctrlrange[2 * a + 1]));
    nominal_[k] = std::clamp(nominal_[k], lower_[k], upper_[k]);
    nominal_kp_[k] = std::clamp(nominal_kp_[k], 0.0, cfg_.max_kp);
    nominal_kd_[k] = std::clamp(nominal_kd_[k], 0.0, cfg_.max_kd);
  }
  if (cfg_.emergency_response == EmergencyResponse::kCrouch) checkCrouchPose();
  const double period_s = cfg_.control_rate_hz > 0 ? 1.0 / cfg_.control_rate_hz : task_->controlTimestep();
  period_us_ = std::max<int64_t>(1, std::llround(period_s * 1e6));
  stale_us_ = std::max<int64_t>(1, std::llround(cfg_.stale_after_s * 1e6));
  // A forged lead shorter than half the stale time cannot starve the watchdog of real states.
  freshness_ = StateFreshness(stale_us_ / 2);
  settle_commands_ = static_cast<int>(std::ceil(cfg_.calibration_settle_s / period_s - 1e-9));
  // The weights never change on the robot: frozen, inference reads them packed for its agent
  // columns. One inference now, so that the packs and buffers exist before the first command.
  model_->freezeForInference();
  obs_ = Mat<float>::Zero(task_->obsDim(), 1);
  model_->actMean(obs_);
}

PolicyRunner::~PolicyRunner() = default;

// A crouch pose the limits would clamp is not the pose the config promises: refuse it.
void PolicyRunner::checkCrouchPose() const {
  if (static_cast<int>(cfg_.crouch_pose.size()) != n_)
    throw std::runtime_error("emergency.crouch_pose has " + std::to_string(cfg_.crouch_pose.size()) +
                             " values; task " + task_->name() + "'s robot has " + std::to_string(n_) + " joints");
  for (int k = 0; k < n_; ++k) {
    const double q = cfg_.crouch_pose[k];
    if (q >= lower_[k] && q <= upper_[k]) continue;
    const char* name = mj_id2name(task_->model(), mjOBJ_JOINT, task_->jointOfAction(k));
    throw std::runtime_error("emergency.crouch_pose: joint " + std::to_string(k) + " (" + (name ? name : "?") + ") at " +
                             std::to_string(q) + " rad is outside [" + std::to_string(lower_[k]) + ", " +
                             std::to_string(upper_[k]) + "] (its range less limits.position_margin)");
  }
}

masa::lcmt_robot_command PolicyRunner::makeCommand() const {
  masa::lcmt_robot_command c{};
  c.num_joints = n_;
  c.position.assign(n_, 0.0);
  c.velocity.assign(n_, 0.0);
  c.torque_ff.assign(n_, 0.0);
  c.kp.assign(n_, 0.0);
  c.kd.assign(n_, 0.0);
  c.runner_id = runner_id_;
  return c;
}

void PolicyRunner::onState(const masa::lcmt_robot_state& s, int64_t rx_us) {
  if (s.num_joints != n_ || static_cast<int>(s.joint_position.size()) != n_) {
    ++states_ignored_;
    return;
  }
  const StateFreshness::Verdict news = freshness_.judge(s.utime, rx_us);
  if (news == StateFreshness::Verdict::kRepeat || news == StateFreshness::Verdict::kAhead) {
    ++states_ignored_;  // a repeat of an old state, or a utime ahead of the clock: no news
    return;
  }
  ++states_received_;
  const double base[13] = {s.base_x,  s.base_y,  s.base_z,  s.base_qw, s.base_qx, s.base_qy, s.base_qz,
                           s.base_vx, s.base_vy, s.base_vz, s.base_wx, s.base_wy, s.base_wz};
  bool finite = allFinite(s.joint_position) && allFinite(s.joint_velocity) && allFinite(s.joint_torque);
  if (s.has_base)
    for (double x : base) finite = finite && std::isfinite(x);
  if (have_state_ && rx_us > state_rx_us_) {
    const double gap = static_cast<double>(rx_us - state_rx_us_);
    interval_us_ = interval_us_ <= 0 ? gap : 0.9 * interval_us_ + 0.1 * gap;
  }
  have_state_ = true;
  state_fresh_ = true;
  state_utime_ = s.utime;
  state_rx_us_ = rx_us;
  if (!finite) {
    if (state_finite_) nonfinite_field_ = "a joint or base value is NaN or infinite";
    state_finite_ = false;
    return;  // q_ keeps the last finite pose, for hold
  }
  std::copy(s.joint_position.begin(), s.joint_position.end(), q_.begin());
  std::copy(s.joint_velocity.begin(), s.joint_velocity.end(), qd_.begin());
  has_base_ = s.has_base && task_->hasRobotBase();
  if (has_base_) {
    std::copy(base, base + 7, base_pose_);
    std::copy(base + 7, base + 13, base_vel_);
  }
}

int64_t PolicyRunner::nextDeadline(int64_t now_us) const {
  if (!have_state_) return INT64_MAX;
  if (command_now_) return now_us;
  if (isLatched(mode_)) return next_due_us_;
  const int64_t stale_at = state_rx_us_ + stale_us_ + 1;
  if (!started_ || (state_fresh_ && state_rx_us_ >= next_due_us_)) return std::min(now_us, stale_at);
  return now_us < next_due_us_ ? std::min(next_due_us_, stale_at) : stale_at;
}

void PolicyRunner::trip(Mode m, std::string why) {
  mode_ = m;
  reason_ = std::move(why);
  for (int k = 0; k < n_; ++k) hold_pose_[k] = std::clamp(q_[k], lower_[k], upper_[k]);
  // The crouch ramp starts where the robot is, not at the last target: after a fall the two differ
  // and a jump to the old target is what the ramp is there to avoid.
  if (crouching()) prev_target_ = hold_pose_;
}

void PolicyRunner::stop(Mode safe, const std::string& why) {
  if (!isLatched(mode_)) trip(safe, why);
}

void PolicyRunner::stopNow(Mode safe, const std::string& why) {
  stop(safe, why);
  command_now_ = true;
}

bool PolicyRunner::orientationBeyondLimit(std::string& why) const {
  if (!has_base_) return false;
  const double w = base_pose_[3], x = base_pose_[4], y = base_pose_[5], z = base_pose_[6];
  const double roll = std::atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y));
  const double pitch = std::asin(std::clamp(2 * (w * y - z * x), -1.0, 1.0));
  if (std::abs(roll) <= cfg_.max_roll && std::abs(pitch) <= cfg_.max_pitch) return false;
  why = "roll " + std::to_string(roll) + " rad, pitch " + std::to_string(pitch) + " rad beyond the limits (" +
        std::to_string(cfg_.max_roll) + ", " + std::to_string(cfg_.max_pitch) + ")";
  return true;
}

bool PolicyRunner::poll(int64_t now_us, masa::lcmt_robot_command& cmd) {
  if (!have_state_) return false;
  if (!started_) {
    started_ = true;
    next_due_us_ = state_rx_us_;
    last_cmd_us_ = now_us - period_us_;
    wall_minus_now_us_ = wallMicros() - now_us;
    for (int k = 0; k < n_; ++k) prev_target_[k] = target_[k] = hold_pose_[k] = std::clamp(q_[k], lower_[k], upper_[k]);
    reason_ = "ramp to the nominal pose";
  }
  bool tripped = false;
  if (!isLatched(mode_)) {
    std::string why;
    if (!state_finite_) {
      trip(safeMode(), "watchdog: state not finite (" + nonfinite_field_ + ")");
      tripped = true;
    } else if (now_us - state_rx_us_ > stale_us_) {
      trip(safeMode(),
           "watchdog: no new state for " + std::to_string((now_us - state_rx_us_) / 1000) + " ms (limit " +
               std::to_string(stale_us_ / 1000) + " ms)");
      tripped = true;
    } else if (orientationBeyondLimit(why)) {
      trip(Mode::kEmergencyStop, "emergency stop: " + why);
      tripped = true;
    }
  }
  if (!tripped && !command_now_ && now_us < next_due_us_) return false;
  command_now_ = false;
  answered_rx_us_ = 0;
  answered_utime_ = 0;
  if (isLatched(mode_)) {
    safeTargets(std::min(now_us - last_cmd_us_, period_us_) * 1e-6);
  } else {
    if (!(state_fresh_ && state_rx_us_ >= next_due_us_)) return false;  // wait for a fresh state
    const double dt = std::min(now_us - last_cmd_us_, period_us_) * 1e-6;
    answered_rx_us_ = state_rx_us_;
    answered_utime_ = state_utime_;
    state_fresh_ = false;
    if (mode_ == Mode::kCalibrating) {
      calibrationTargets(dt);
    } else if (!policyTargets(dt)) {
      trip(safeMode(), "policy output not finite");
      safeTargets(dt);
    }
  }
  finishCommand(now_us, cmd);
  if (to_policy_) {  // the last calibration command is out as one
    to_policy_ = false;
    mode_ = Mode::kPolicy;
    reason_ = "at the nominal pose: the policy takes over";
  }
  // The next command answers the state the robot sends about one period after the one just
  // answered: the first received after that time less half a state interval (so that a robot
  // whose state rate equals the control rate is answered every period, not every other).
  if (answered_rx_us_ > 0) {
    const int64_t slack = std::min<int64_t>(period_us_ / 2, static_cast<int64_t>(interval_us_ / 2));
    next_due_us_ = answered_rx_us_ + period_us_ - slack;
  } else {
    next_due_us_ = now_us + period_us_;
  }
  return true;
}

void PolicyRunner::calibrationTargets(double dt_s) {
  const double step = cfg_.calibration_max_rate * dt_s;
  bool arrived = true;
  for (int k = 0; k < n_; ++k) {
    target_[k] = prev_target_[k] + std::clamp(nominal_[k] - prev_target_[k], -step, step);
    arrived = arrived && target_[k] == nominal_[k];
    vel_[k] = tau_[k] = 0.0;
    kp_[k] = nominal_kp_[k];
    kd_[k] = nominal_kd_[k];
  }
  if (arrived && settled_++ >= settle_commands_) to_policy_ = true;
}

bool PolicyRunner::policyTargets(double dt_s) {
  task_->setMeasuredState(q_.data(), qd_.data(), has_base_ ? base_pose_ : nullptr, has_base_ ? base_vel_ : nullptr,
                          last_action_.data());
  task_->observe(obs_.data());
  const auto mean = model_->actMean(obs_);
  for (int k = 0; k < n_; ++k) {
    const double a = mean(k, 0);
    if (!std::isfinite(a)) return false;
    action_[k] = std::clamp(a, -cfg_.action_clip, cfg_.action_clip);
  }
  task_->jointCommand(action_.data(), target_.data(), vel_.data(), tau_.data(), kp_.data(), kd_.data());
  const double step = cfg_.max_target_rate * dt_s;
  for (int k = 0; k < n_; ++k) {
    last_action_[k] = std::clamp(action_[k], -1.0, 1.0);  // what the task records
    target_[k] = std::clamp(target_[k], prev_target_[k] - step, prev_target_[k] + step);
  }
  ++policy_steps_;
  return allFinite(target_) && allFinite(vel_) && allFinite(tau_) && allFinite(kp_) && allFinite(kd_);
}

void PolicyRunner::warmUp() {
  if (mode_ != Mode::kPolicy || !state_finite_) return;
  // The same calls as policyTargets(): the task's data is rewritten from the state on every step,
  // so the next command is the same with or without this.
  task_->setMeasuredState(q_.data(), qd_.data(), has_base_ ? base_pose_ : nullptr, has_base_ ? base_vel_ : nullptr,
                          last_action_.data());
  task_->observe(obs_.data());
  model_->actMean(obs_);
}

void PolicyRunner::safeTargets(double dt_s) {
  if (crouching()) {
    const double step = cfg_.crouch_max_rate * dt_s;
    for (int k = 0; k < n_; ++k) {
      target_[k] = prev_target_[k] + std::clamp(cfg_.crouch_pose[k] - prev_target_[k], -step, step);
      vel_[k] = tau_[k] = 0.0;
      kp_[k] = cfg_.crouch_kp;
      kd_[k] = cfg_.crouch_kd;
    }
    return;
  }
  const bool hold = mode_ == Mode::kHold;
  for (int k = 0; k < n_; ++k) {
    target_[k] = hold_pose_[k];
    vel_[k] = tau_[k] = 0.0;
    kp_[k] = hold ? cfg_.hold_kp : 0.0;
    kd_[k] = hold ? cfg_.hold_kd : cfg_.damping_kd;
  }
}

void PolicyRunner::finishCommand(int64_t now_us, masa::lcmt_robot_command& cmd) {
  for (int k = 0; k < n_; ++k) {
    const double q = std::clamp(target_[k], lower_[k], upper_[k]);
    target_[k] = prev_target_[k] = q;
    cmd.position[k] = q;
    cmd.velocity[k] = std::clamp(vel_[k], -cfg_.max_target_rate, cfg_.max_target_rate);
    cmd.torque_ff[k] = std::clamp(tau_[k], -torque_limit_[k], torque_limit_[k]);
    cmd.kp[k] = std::clamp(kp_[k], 0.0, cfg_.max_kp);
    cmd.kd[k] = std::clamp(kd_[k], 0.0, cfg_.max_kd);
  }
  // Not the wall clock read now: poll() took the time before the policy ran (up to milliseconds
  // on a loaded machine), and the limits above are per interval of now_us.
  cmd.utime = now_us + wall_minus_now_us_;
  cmd.state_utime = answered_utime_;
  cmd.runner_id = runner_id_;
  cmd.sequence = sequence_++;
  cmd.mode = static_cast<int8_t>(mode_);
  last_cmd_us_ = now_us;
}

}  // namespace masa::deploy
