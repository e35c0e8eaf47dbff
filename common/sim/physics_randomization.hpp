// Randomized physics for a task's episodes (issue #52): `env.randomization` in the task config, off
// when absent (then nothing here runs and the task is bit for bit what it was). Each episode draws,
// from the reset's seeded generator, scales of link masses (inertia alike), geom friction, joint
// damping and friction loss, actuator strength and the task's PD gains, centre-of-mass offsets
// (com_offsets.hpp), a control latency, and an observation bias; each step adds observation noise,
// and may push the robot base (episode_pushes.hpp). The draws are in the episode's statistics.
//
// Symmetric by default: elements the robot's symmetry carries onto each other (the limbs' joints,
// their bodies, those bodies' geoms, their actuators: the orbits of the spec's action permutation)
// get one draw, so every randomized model keeps the symmetry MASA assumes and `masa_verify` still
// proves the spec on it. `per_limb: true` draws every element on its own (a robot whose limbs
// differ, as real ones do). Observation noise and bias are drawn per entry with one spread: the
// same distribution for every limb, symmetric in distribution but not sample by sample, so the
// verifier is run without them.
//
// The drawn episode is task state: copied and saved with the task (task_state.cpp), so a resumed
// actor and the verifier's transformed copies see the same physics.
#pragma once

#include <span>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "common/core/types.hpp"
#include "common/sim/env_params.hpp"
#include "common/symmetry/symmetry_spec.hpp"

namespace masa::task {

struct ScaleRange {
  double lo = 1.0, hi = 1.0;
  bool active() const { return lo != 1.0 || hi != 1.0; }
};

struct RandomizationConfig {
  bool enabled = false;   // the section is present
  bool per_limb = false;  // every element its own draw (breaks the symmetry on purpose)
  ScaleRange mass, geom_friction, joint_damping, joint_friction, actuator_strength;
  // Scales of the task's own PD gains (A1 Beam, TriFinger, YAML tasks with PD actuation): a draw
  // per joint orbit, like the damping.
  ScaleRange pd_kp, pd_kd;
  // Pushes: a horizontal velocity change of the robot base, size uniform in [0, push_velocity] m/s,
  // direction uniform; each control step pushes with probability step / push_interval_s (on average
  // one push every push_interval_s seconds). 0: none.
  double push_velocity = 0.0, push_interval_s = 0.0;
  // Centre-of-mass offsets, metres: each world component (at the model's reference pose) uniform in
  // [-com_offset, com_offset]. Symmetric: the offset of a body's image is the image of its offset
  // (S_i d for the symmetry's spatial map S_i), so the robot base can only move within the
  // symmetry's fixed subspace (a mirror's plane, a rotation's axis); see com_offsets.hpp.
  double com_offset = 0.0;
  // Control latency in control steps, uniform per episode in [lo, hi]: the whole part delays the
  // action by whole steps, the fraction by that share of the step's physics substeps.
  double latency_lo = 0.0, latency_hi = 0.0;
  double obs_noise_std = 0.0;  // per entry and step, Gaussian
  double obs_bias = 0.0;       // per entry and episode, uniform in [-obs_bias, obs_bias]

  // Reads env.randomization (absent: disabled); ranges are refused naming the key (min above max,
  // a negative scale or latency, NaN or infinity, an unknown key).
  static RandomizationConfig read(EnvParams& params);
};

class PhysicsRandomization {
 public:
  // `model` is the task's own copy, written by drawEpisode; the nominal values are kept from it.
  // action_joint / action_actuator: the joint and actuator of each action (Task's binding).
  PhysicsRandomization(const RandomizationConfig& config, mjModel* model, const sym::SymmetrySpec& spec,
                       const std::vector<int>& action_joint, const std::vector<int>& action_actuator);
  ~PhysicsRandomization();
  PhysicsRandomization(const PhysicsRandomization&) = delete;
  PhysicsRandomization& operator=(const PhysicsRandomization&) = delete;

  const RandomizationConfig& config() const { return config_; }
  // This episode's physics, from the nominal model; draws in a fixed order from rng.
  void drawEpisode(Rng& rng);
  // The episode's draws as numbers (task state), and back (re-applied to the model).
  void save(std::vector<double>& out) const;
  std::size_t load(std::span<const double> in, const std::string& task_name);  // values read

  // The episode's latency: whole control steps, and the fraction of a step beyond them.
  int latencySteps() const { return latency_steps_; }
  double latencyFraction() const { return latency_ - latency_steps_; }
  bool perturbsObservations() const { return config_.obs_noise_std > 0.0 || config_.obs_bias > 0.0; }
  // Adds the episode's bias and a step's noise (from noise_rng) to an observation.
  void perturbObservation(float* obs, int n, Rng& noise_rng) const;
  // Actuator a's gear before the draws (a robot's motor driver converts torque with the nominal gear,
  // so a weaker motor gives less torque for the same command: masa_sim_robot).
  double nominalGear(int a) const { return gear0_[6 * static_cast<std::size_t>(a)]; }
  // The model's own values before the draws, to say what a draw changed.
  double nominalMass(int b) const { return mass0_[static_cast<std::size_t>(b)]; }
  double nominalFriction(int g) const { return friction0_[3 * static_cast<std::size_t>(g)]; }
  double nominalDamping(int v) const { return damping0_[static_cast<std::size_t>(v)]; }
  // The episode's draws in brief, for its statistics (masa_eval, episode results): the mean drawn
  // scale of each kind over its groups (symmetric: one per orbit; per limb: one per element), the
  // latency in control steps. Names "physics: <key>" in drawNames() order.
  static const std::vector<std::string>& drawNames();
  void summarize(std::vector<double>& out) const;
  // The episode's scale of action k's PD gains (1 when not drawn).
  double kpScale(int action) const { return kp_scale_[action_group_[static_cast<std::size_t>(action)]]; }
  double kdScale(int action) const { return kd_scale_[action_group_[static_cast<std::size_t>(action)]]; }
  // The orbit of each element kind (symmetric mode's draw groups), exposed for tests.
  const std::vector<int>& bodyOrbits() const { return body_orbit_; }

 private:
  void apply();

  RandomizationConfig config_;
  mjModel* m_;
  int obs_dim_;
  // Nominal values, and each element's draw group (its orbit, or itself per limb).
  std::vector<double> mass0_, inertia0_, friction0_, damping0_, frictionloss0_, gear0_, ipos0_;
  std::vector<double> body_rot0_;               // each body's world orientation at qpos0 (3x3, row major)
  std::vector<std::vector<int>> body_image_;    // [element][body]: the body T_i carries it onto (-1: unknown)
  std::vector<double> spatial_map_;             // [element]: the symmetry's 3x3 spatial map S_i (row major)
  int base_body_ = -1;                          // the robot base's body (-1: none)
  std::vector<double> com_offset_;              // the episode's offset of each body, world frame (3 per body)
  std::vector<int> body_orbit_, geom_orbit_, dof_orbit_, actuator_orbit_, action_group_;
  int n_body_groups_ = 0, n_geom_groups_ = 0, n_dof_groups_ = 0, n_actuator_groups_ = 0;
  // The episode's draws: a scale per group and kind, the latency, the bias per observation entry.
  std::vector<double> body_scale_, geom_scale_, damping_scale_, frictionloss_scale_, actuator_scale_, kp_scale_, kd_scale_;
  double latency_ = 0.0;
  int latency_steps_ = 0;
  mjData* scratch_ = nullptr;  // mj_setConst's workspace, made once
  std::vector<double> obs_bias_;
};

}  // namespace masa::task
