// Randomized physics for a task's episodes (issue #52): `env.randomization` in the task config, off
// when absent (then nothing here runs and the task is bit for bit what it was). Each episode draws,
// from the reset's seeded generator, scales of link masses (inertia alike), geom friction, joint
// damping and friction loss, and actuator strength, a control latency, and an observation bias;
// each step adds observation noise.
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
  // The orbit of each element kind (symmetric mode's draw groups), exposed for tests.
  const std::vector<int>& bodyOrbits() const { return body_orbit_; }

 private:
  void apply();

  RandomizationConfig config_;
  mjModel* m_;
  int obs_dim_;
  // Nominal values, and each element's draw group (its orbit, or itself per limb).
  std::vector<double> mass0_, inertia0_, friction0_, damping0_, frictionloss0_, gear0_;
  std::vector<int> body_orbit_, geom_orbit_, dof_orbit_, actuator_orbit_;
  int n_body_groups_ = 0, n_geom_groups_ = 0, n_dof_groups_ = 0, n_actuator_groups_ = 0;
  // The episode's draws: a scale per group and kind, the latency, the bias per observation entry.
  std::vector<double> body_scale_, geom_scale_, damping_scale_, frictionloss_scale_, actuator_scale_;
  double latency_ = 0.0;
  int latency_steps_ = 0;
  mjData* scratch_ = nullptr;  // mj_setConst's workspace, made once
  std::vector<double> obs_bias_;
};

}  // namespace masa::task
