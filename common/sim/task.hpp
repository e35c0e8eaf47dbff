// A robot task simulated in MuJoCo: reset from a passed-in generator, step with frame skip and
// clamped controls, observation in the symmetry spec's layout, reward term by term, termination
// kept apart from time-limit truncation, and episode statistics.
//
// A concrete task (one folder per task under tasks/) fills in the hooks below; everything common
// lives here, including applying a symmetry T_i to the WHOLE task state (MuJoCo joints through
// the spec's `mujoco` binding, the last action, and the task's own extras such as a goal pose),
// which the physics verifier uses.
//
// Actions arrive in [-1, 1] in the spec's action order; the task maps them to actuators (by the
// spec's actuator names) and scales them. Nothing here allocates after construction.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/core/types.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "common/sim/env_params.hpp"
#include "common/sim/goal_relabeling.hpp"
#include "common/sim/mujoco_model.hpp"
#include "common/sim/physics_randomization.hpp"

namespace masa::task {

struct StepOutcome {
  double reward = 0.0;
  bool terminated = false;  // the episode failed or ended for good: no value bootstrap
  bool truncated = false;   // time limit reached: bootstrap from the final observation
};

struct EpisodeStats {
  double ret = 0.0;
  int length = 0;
  std::vector<double> term_sums;  // per reward term, weighted, in rewardTermNames() order
  std::vector<double> physics;    // env.randomization's draws of the episode, in physicsDrawNames() order
  bool has_success = false;
  bool success = false;
  bool terminated = false;
  bool truncated = false;
};

// T_i of one free joint (the spec's kinds, see docs/verifier.md): position, orientation (qpos, 7
// values), velocity and warm start (qvel, 6 values each, angular part in the body frame).
void transformFreeJoint(const sym::Group& group, int i, sym::FreeJointKind kind, double* qpos, double* qvel,
                        double* warm);
// The 3x3 blocks that act on a free joint's linear and angular velocity under T_i.
void freeJointVelocityBlocks(const sym::Group& group, int i, sym::FreeJointKind kind, Eigen::Matrix3d& linear,
                             Eigen::Matrix3d& angular);

class Task {
 public:
  virtual ~Task();
  Task(const Task&) = delete;
  Task& operator=(const Task&) = delete;

  const std::string& name() const { return name_; }
  // Cached: SymmetrySpec recomputes them from its layout, and step() asks several times per step.
  int obsDim() const { return obs_dim_; }
  int actDim() const { return act_dim_; }
  const sym::SymmetrySpec& spec() const { return spec_; }
  double controlTimestep() const;  // seconds per step(): frame_skip * model timestep
  int maxEpisodeSteps() const { return max_episode_steps_; }

  // Reward terms: the task's terms (weighted by env.weights.<term>), then "termination".
  const std::vector<std::string>& rewardTermNames() const { return term_names_; }
  const std::vector<double>& rewardTerms() const { return terms_; }  // last step, weighted

  // A new episode from rng: with env.randomization, its physics drawn first
  // (common/sim/physics_randomization.hpp), then the task's own reset.
  void reset(Rng& rng);
  void observe(float* out) const;             // obsDim() values (with env.randomization's noise)
  StepOutcome step(const float* action);      // actDim() values, clamped to [-1, 1]
  StepOutcome step(std::span<const float> action);  // the same, checking the size
  // The physics of step() alone: clamping, actuation, frame-skip substeps (with their control
  // hooks). No pose refresh, reward, termination or statistics: for benchmarks that separate the
  // simulator's cost from the task's, replaying the same actions along the same trajectory.
  void advancePhysics(const float* action);
  const EpisodeStats& episode() const { return episode_; }
  // The task's own measures of how far an episode got (metres along the beam, the cube's pose
  // error, seconds the pole stayed up), read at the end of an episode by evaluations. The names
  // carry their units and are the same for every episode.
  virtual std::vector<std::string> progressNames() const { return {}; }
  // Whether episodes of this task end in success or failure (TriFinger: the goal pose reached);
  // tasks that only score (the walkers) have no success to report or plot.
  bool measuresSuccess() const { return hasSuccessMeasure(); }
  virtual void progress(double* out) const {}
  // A goal-conditioned task's relabeling (common/sim/goal_relabeling.hpp), with this instance's
  // reward weights and tolerances; null for a task that declares no goal (the default).
  virtual std::unique_ptr<GoalRelabeling> goalRelabeling() const { return nullptr; }

  // Whole-state symmetry: the state becomes T_i of itself (then mj_forward). The verifier compares
  // step(T s, T a) with T step(s, a).
  void applySymmetry(int i);
  // Copies the full state (simulator and task extras) of another instance of the same task.
  void copyStateFrom(const Task& other);
  // The full state as numbers (common/sim/task_state.cpp): the simulator's (time, qpos, qvel, act,
  // ctrl, warm start, applied forces, mocap, user data), the last action, the episode so far and
  // the task's extras. saveState appends; loadState takes exactly what saveState of the same task
  // and model wrote (a size that differs throws, naming it), then mj_forward. An actor saved with
  // its environments goes on as if it had not stopped.
  void saveState(std::vector<double>& out) const;
  void loadState(std::span<const double> in);

  // --- deployment: a robot's measured state in place of the simulator's own (masa_deploy) ---
  // The joint command the task's actuation turns `action` (action order, clamped to [-1, 1]) into,
  // for a robot that runs per joint  torque = kp (position - q) + kd (velocity - qdot) + torque_ff.
  // Each output holds actDim() values. False when the task's actuation is not such a per-joint
  // law (the default): such a task cannot be deployed by masa_deploy.
  virtual bool jointCommand(const double* action, double* position, double* velocity, double* torque_ff, double* kp,
                            double* kd) const {
    return false;
  }
  // Writes a measured state into data() the way the simulator holds it, then refreshes body poses
  // as step() does, so that observe() builds the observation by the task's own code: joint angles
  // and velocities (action order), the robot base (spec mujoco.free_joints, kind robot_base) as
  // position, quaternion (w, x, y, z), world linear and body angular velocity (null: left as they
  // are), and the last action (action order, what the task records after clamping).
  void setMeasuredState(const double* joint_pos, const double* joint_vel, const double* base_pose7,
                        const double* base_vel6, const double* last_action);
  // "" when the observation depends only on what setMeasuredState writes, else why not (a joint
  // that no action drives and that is not the robot base: a ball, a cube).
  std::string measuredStateGap() const;
  bool hasRobotBase() const { return base_qadr_ >= 0; }
  // The task's termination test on the current state (a fall), without stepping.
  bool terminatedNow() const { return isTerminated(); }
  int actuatorOfAction(int k) const { return action_actuator_[k]; }
  int jointOfAction(int k) const { return action_joint_[k]; }

  const mjModel* model() const { return model_->get(); }
  // The episode's randomized physics (null without env.randomization).
  const PhysicsRandomization* randomization() const { return randomization_.get(); }
  // The names of EpisodeStats::physics: empty without env.randomization.
  std::vector<std::string> physicsDrawNames() const {
    return randomization_ ? PhysicsRandomization::drawNames() : std::vector<std::string>{};
  }
  const MujocoModel& mujocoModel() const { return *model_; }  // with its file path and named lookups
  const mjData* data() const { return data_; }
  mjData* data() { return data_; }
  const std::vector<double>& lastAction() const { return last_action_; }  // clamped, action order
  // The MuJoCo joint each action drives (-1: none), in action order.
  const std::vector<int>& actionJoints() const { return action_joint_; }
  // What step() does to the controls before the first substep (clamping, applyAction, the first
  // substep's control hook), without stepping: mj_forward then gives the actuator forces of `action`.
  void actuate(const float* action);
  // The joint-space map of T_i on velocities (nv x nv): qvel(T s) = P qvel(s). Generalized forces
  // transform alike (P is orthogonal), the mass matrix as P M P^T.
  Eigen::MatrixXd velocityMap(int i) const;

 protected:
  // `term_names` are the task's reward terms; their weights come from env.weights.<term>.
  Task(std::string name, std::shared_ptr<const MujocoModel> model, sym::SymmetrySpec spec, EnvParams& params,
       const std::vector<std::pair<std::string, double>>& terms_with_default_weights);

  // --- hooks ---
  // Called after mj_resetData: set the initial state (and task extras) from rng. mj_forward follows.
  virtual void resetTask(Rng& rng) = 0;
  virtual void writeObservation(float* out) const = 0;
  // Unweighted value of each reward term after a step (the base class applies the weights).
  virtual void computeRewardTerms(double* raw_terms) const = 0;
  virtual bool isTerminated() const = 0;
  // Sets data()->ctrl from the clamped action (action order). Default: ctrl = action scaled into
  // each actuator's ctrlrange midpoint +- half-range (i.e. [-1,1] maps onto ctrlrange).
  virtual void applyAction(const double* action);
  // Called before every physics substep (PD loops compute torques here).
  virtual void beforeSubstep() {}
  // Called after the substeps of a step, before reward and termination (e.g. route re-anchoring).
  // Body and geom poses (xpos, xmat, geom_xpos, ...) are refreshed for the final state before this
  // hook; velocity-derived quantities (cvel, actuator_velocity) are those of the last substep.
  virtual void afterStep() {}
  virtual bool hasSuccessMeasure() const { return false; }
  virtual bool isSuccess() const { return false; }
  // Task-owned state beyond qpos/qvel/ctrl/last action (a goal pose, a route): under T_i, and as
  // numbers for copies and saved states. loadExtras reads what saveExtras wrote, all of it (the
  // base class checks that nothing is left over); a count that cannot be throws.
  virtual void transformExtras(int i) {}
  virtual void saveExtras(std::vector<double>& out) const {}
  virtual void loadExtras(std::span<const double> in) {}

  // --- helpers for tasks ---
  int frameSkip() const { return frame_skip_; }
  // The episode's scales of action k's PD gains (env.randomization.pd_kp_scale / pd_kd_scale; 1
  // without): a task's own PD loop multiplies its gains by them.
  double kpScale(int k) const { return randomization_ ? randomization_->kpScale(k) : 1.0; }
  double kdScale(int k) const { return randomization_ ? randomization_->kdScale(k) : 1.0; }
  // The weight env.weights.<term> of one of the task's reward terms; the termination reward.
  double termWeight(const std::string& term) const;
  double terminationReward() const { return termination_reward_; }
  // The paper's "joints power consumption" in the convention its weights were tuned for
  // (IsaacGym's electricity cost): sum over actions of |a_k * qdot_k| * energy_velocity_scale * w_k,
  // with a_k the clamped action in [-1, 1], qdot_k its joint's velocity (rad/s), and w_k = 1 (the
  // Ant's convention) or, with env.energy_effort_weighting, the motor's gear over the largest gear
  // (the Humanoid's). Physical power |torque * qdot| would be gear times larger and swamp the
  // other terms at the paper's weights.
  double jointPower() const;
  // For a task that drives plain joint motors through the default applyAction: the joint command
  // a torque-controlled robot runs, torque_ff = the motor's torque for `action`, kp = kd = 0, and
  // `pose` (the task's start pose, action order) as position targets, which only the runner's
  // calibration ramp and limits read. False when an actuator is not such a motor.
  bool motorJointCommand(const double* action, const double* pose, double* position, double* velocity,
                         double* torque_ff, double* kp, double* kd) const;

  std::shared_ptr<const MujocoModel> model_;
  mjData* data_ = nullptr;

 private:
  void bindActuators();
  void setControls(const float* action);  // clamp, remember as the last action, applyAction
  void pushIfDue();                       // env.randomization's push of this step (episode_pushes.hpp)
  void transformJoints(int i);
  // mj_forward for a state set from outside (loaded, transformed): the derived quantities, while
  // the two parts of the state mj_forward writes stay as set. It normalizes the quaternions in qpos
  // again (not idempotent in floating point) and leaves its solution in the warm start, where the
  // next step starts from; either would make the next step differ from the state's own.
  void forwardKeepingState();

  std::string name_;
  sym::SymmetrySpec spec_;
  int obs_dim_, act_dim_;
  int frame_skip_;
  int max_episode_steps_;
  double termination_reward_;
  double energy_velocity_scale_;
  bool energy_effort_weighting_ = false;
  std::vector<double> effort_ratio_;  // per action: gear / max gear, or 1
  std::vector<std::string> term_names_;
  std::vector<double> weights_;
  std::vector<double> terms_, raw_terms_;
  std::vector<int> action_actuator_, action_joint_;
  int base_qadr_ = -1, base_vadr_ = -1;  // the robot base free joint's qpos / qvel address
  std::vector<double> last_action_, action_scratch_;
  std::vector<double> qpos_scratch_, qvel_scratch_, ctrl_scratch_;
  EpisodeStats episode_;
  // env.randomization: the task's own copy of the model, drawn anew each episode; the commanded
  // actions of the latency's last steps (newest last, clamped); the episode's noise seed.
  std::unique_ptr<PhysicsRandomization> randomization_;
  std::vector<std::vector<double>> commanded_;
  double noise_seed_ = 0.0;
};

}  // namespace masa::task
