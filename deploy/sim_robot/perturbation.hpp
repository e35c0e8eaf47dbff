// The perturbation of masa_sim_robot (issue #52, item 2): a robot that is not the model the policy
// trained on. It uses the keys of a task's env.randomization (common/sim/physics_randomization.hpp),
// given as --perturb KEY=VALUE (KEY with or without "env.randomization.") and/or a YAML file of them
// (--perturb-file; a mapping of the keys, or one with env.randomization or randomization inside).
// A value is fixed (one number, or [v, v]) or a range drawn from the robot's --seed. The section
// replaces the policy's own training randomization: the robot is one robot, drawn once.
//
// On the robot the keys mean what they mean on a real one: masses, friction, damping and gear
// change the model; a weaker motor gives less torque for the same command (the driver converts with
// the nominal gear: SimRobot); the latency delays every command by latency x control period; the
// observation noise and bias go onto the joint angles and velocities the robot reports.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/core/types.hpp"
#include "common/sim/physics_randomization.hpp"
#include "common/sim/task.hpp"
#include "masa/lcmt_robot_state.hpp"

namespace masa::deploy {

// env with env.randomization replaced by the perturbation (env itself unchanged); origin records
// "--perturb" or the file for each key, so a bad range is refused naming both. No assignment and no
// file: env as it is, and *perturbed false.
YAML::Node perturbedEnv(const YAML::Node& env, const std::vector<std::string>& assignments, const std::string& file,
                        std::map<std::string, std::string>& origin, bool* perturbed);

// What the drawn robot is, read back from its model against the nominal one: total mass, and the
// mean ratio of geom friction, joint damping and gear ("mass 14.3 kg (model 12.0 kg), ...").
std::string describePerturbation(const task::Task& task);

// The reported state's sensor errors: a bias per joint angle and velocity, drawn once, and Gaussian
// noise every message (both from the config's obs_bias and obs_noise_std; one seeded generator).
class StateNoise {
 public:
  StateNoise(const task::RandomizationConfig& config, int num_joints, Rng& rng);
  bool active() const { return std_ > 0.0 || !bias_.empty(); }
  void apply(masa::lcmt_robot_state& state);

 private:
  double std_;
  std::vector<double> bias_;  // angles then velocities; empty without obs_bias
  Rng rng_;
};

}  // namespace masa::deploy
