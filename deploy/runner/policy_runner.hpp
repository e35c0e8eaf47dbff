// The policy runner's logic, without LCM: newest state in, joint commands out, on a clock the
// caller passes (microseconds of a steady clock), so tests can drive it step by step.
//
// A command is computed from the first state received at or after its due time (so the state it
// answers is as fresh as the robot makes them) and published at once; the next is due one period
// after the state just answered, less half the robot's state interval. Modes, in order:
//   calibrating : targets ramp from the first measured pose to the nominal pose (the task's
//                 command for action 0) at most calibration.max_rate, then hold it settle_s;
//   policy      : observation from the state through the task's own observation code
//                 (Task::setMeasuredState + Task::observe), the policy mean, the task's joint
//                 command (Task::jointCommand), then the limits;
//   damping / hold (watchdog), emergency stop: latched until restart. The emergency stop (base
//                 roll or pitch beyond its limit) damps, or with emergency.response crouch ramps
//                 the targets from the measured pose to emergency.crouch_pose at most
//                 crouch_max_rate and holds it there (walk-these-ways' fall response).
// Every command, in every mode, passes the limits: targets inside the model's joint range less a
// margin, at most max_target_rate per second away from the previous target (policy mode), gains
// and feed-forward torques within their bounds.
// Watchdog: no new state (utime advancing, deploy/runner/state_freshness.hpp) for stale_after_s
// gives the safe command by
//   last state + stale_after_s + one period   (watchdogBoundS());
// a non-finite state (or policy output) gives it at once. Nothing allocates after construction.
#pragma once

#include <climits>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/model/inference_policy.hpp"
#include "common/policy/policy_file.hpp"
#include "common/sim/registry.hpp"
#include "deploy/runner/deploy_config.hpp"
#include "deploy/runner/state_freshness.hpp"
#include "masa/lcmt_robot_command.hpp"
#include "masa/lcmt_robot_state.hpp"

namespace masa::deploy {

enum class Mode : int8_t { kCalibrating = 0, kPolicy = 1, kDamping = 2, kHold = 3, kEmergencyStop = 4 };
const char* modeName(Mode m);
inline bool isLatched(Mode m) { return m == Mode::kDamping || m == Mode::kHold || m == Mode::kEmergencyStop; }

class PolicyRunner {
 public:
  // Builds the task exactly as trained (the policy file's config) and checks that it can be
  // deployed: its actuation is a per-joint PD law and its observation needs only joint and base
  // state. Throws std::runtime_error saying why not.
  PolicyRunner(policy::LoadedPolicy& policy, const DeployConfig& config, int64_t runner_id);
  ~PolicyRunner();

  int numJoints() const { return n_; }
  // What it acts with: the policy half of the file's model, frozen (its parameters cannot be written).
  model::InferencePolicy<float>& policy() { return *model_; }
  double periodS() const { return period_us_ * 1e-6; }
  double watchdogBoundS() const { return (stale_us_ + period_us_) * 1e-6; }
  Mode mode() const { return mode_; }
  int64_t policySteps() const { return policy_steps_; }
  const std::vector<double>& nominalPose() const { return nominal_; }
  const std::vector<double>& lowerLimit() const { return lower_; }
  const std::vector<double>& upperLimit() const { return upper_; }
  const std::vector<double>& torqueLimit() const { return torque_limit_; }
  // In the emergency stop with the crouch response: the targets ramp to the crouch pose.
  bool crouching() const { return mode_ == Mode::kEmergencyStop && cfg_.emergency_response == EmergencyResponse::kCrouch; }
  // Why the last mode change happened ("" before any): for the log.
  const std::string& reason() const { return reason_; }

  // A state decoded by the wire guard, received at rx_us. Only the newest is kept; one with the
  // wrong joint count is ignored (counted), one whose utime does not advance is not fresh.
  void onState(const masa::lcmt_robot_state& s, int64_t rx_us);
  // Fills `cmd` (utime, sequence and runner_id too) and returns true when a command is to be
  // published now. `cmd` must have been made by makeCommand(). The command's utime is now_us on
  // the wall clock (the offset fixed at the first command): the instant its rate limits were
  // computed for, so the target rates the robot sees between utimes are the limits.
  bool poll(int64_t now_us, masa::lcmt_robot_command& cmd);
  // The latest time poll() must be called again (for the LCM wait); INT64_MAX: only on a state.
  int64_t nextDeadline(int64_t now_us) const;
  // When the next command is due (it answers the first state received from then on); INT64_MAX
  // before the first state.
  int64_t nextCommandDueUs() const { return started_ ? next_due_us_ : INT64_MAX; }
  // Runs the observation and the policy on the newest state and throws the result away: called
  // shortly before a command is due, it brings the network's weights back into the cache that other
  // processes evicted since the last command (measured under load: step p50 32 -> 12-17 us).
  // Changes no command. Nothing allocates.
  void warmUp();
  // Switches to the safe command (latched), saying why; it goes out at the next command's due time
  // (the last command keeps its period: the policy step limit).
  void stop(Mode safe, const std::string& why);
  // The same, and the next poll() gives the command at once, due or not: the run is ending (a
  // signal, another runner, an error) and the safe command must be the last one on the wire. When
  // already latched, the latched command goes out at once.
  void stopNow(Mode safe, const std::string& why);
  // The configured safe command's mode (safe.mode): kDamping or kHold.
  Mode safeMode() const { return cfg_.safe_mode == SafeMode::kHold ? Mode::kHold : Mode::kDamping; }
  // A command message sized for this robot.
  masa::lcmt_robot_command makeCommand() const;
  // Receive time of the state the last command answered (0: none, e.g. a watchdog command).
  int64_t lastAnsweredRxUs() const { return answered_rx_us_; }

  bool hasState() const { return have_state_; }
  int64_t statesReceived() const { return states_received_; }
  int64_t statesIgnored() const { return states_ignored_; }
  // Whether each state was news (its utime against the receive clock): refusals and resyncs.
  const StateFreshness& freshness() const { return freshness_; }

 private:
  void trip(Mode m, std::string why);
  void calibrationTargets(double dt_s);
  bool policyTargets(double dt_s);
  void safeTargets(double dt_s);
  void checkCrouchPose() const;
  void finishCommand(int64_t now_us, masa::lcmt_robot_command& cmd);
  bool orientationBeyondLimit(std::string& why) const;

  DeployConfig cfg_;
  int64_t runner_id_;
  std::unique_ptr<task::TaskFactory> factory_;
  std::unique_ptr<task::Task> task_;
  // The policy half of the file's model (no critic on the robot), frozen for inference.
  std::unique_ptr<model::InferencePolicy<float>> model_;
  int n_ = 0;
  int64_t period_us_ = 0, stale_us_ = 0;
  int settle_commands_ = 0;

  // Newest state.
  bool have_state_ = false, state_fresh_ = false, state_finite_ = true;
  int64_t state_utime_ = 0, state_rx_us_ = 0;
  std::vector<double> q_, qd_;
  double base_pose_[7] = {0, 0, 0, 1, 0, 0, 0}, base_vel_[6] = {};
  bool has_base_ = false;
  std::string nonfinite_field_;
  int64_t states_received_ = 0, states_ignored_ = 0;
  StateFreshness freshness_;  // its lead: half the watchdog's stale_after_s

  // Commands.
  Mode mode_ = Mode::kCalibrating;
  std::string reason_;
  int64_t next_due_us_ = 0, last_cmd_us_ = 0, sequence_ = 0, answered_rx_us_ = 0, answered_utime_ = 0;
  int64_t wall_minus_now_us_ = 0;  // cmd.utime - now_us, fixed at the first command
  int settled_ = 0;
  bool to_policy_ = false;
  bool command_now_ = false;  // stopNow(): the next poll() publishes, due or not
  double interval_us_ = 0;  // mean time between states (exponential average)
  int64_t policy_steps_ = 0;
  bool started_ = false;
  std::vector<double> target_, prev_target_, vel_, tau_, kp_, kd_;
  std::vector<double> nominal_, nominal_kp_, nominal_kd_, lower_, upper_, torque_limit_;
  std::vector<double> action_, last_action_, hold_pose_;
  Mat<float> obs_;
};

}  // namespace masa::deploy
