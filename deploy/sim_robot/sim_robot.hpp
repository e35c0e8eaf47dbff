// The robot side of masa_sim_robot: a task's MuJoCo model driven as a robot's joint controller
// drives its motors. It reads the state a robot reports (joint angles, velocities and torques, the
// base pose and twist from the task's robot-base free joint) and applies a command with the PD law
// at every physics step: torque = kp (position - q) + kd (velocity - qdot) + torque_ff, divided by
// the actuator's nominal gear (so a perturbed gear, a weaker or stronger motor, changes the torque)
// and clipped to its control range (a non-finite result becomes 0).
#pragma once

#include <vector>

#include "common/sim/task.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "masa/lcmt_robot_command.hpp"
#include "masa/lcmt_robot_state.hpp"

namespace masa::deploy {

// What the reported state gets wrong on purpose (tests of the runner's safety): from nan_after_s
// of simulated time NaN joint angles; from tilt_after_s a base rolled by tilt_rad more than it is
// (an IMU's view of a fall). Negative: never.
struct StateFaults {
  double nan_after_s = -1;
  double tilt_after_s = -1;
  double tilt_rad = 1.0;
};

class SimRobot {
 public:
  // Resolves each action's joint and actuator; throws std::runtime_error for an action that drives
  // no joint. The task must outlive the robot.
  SimRobot(task::Task& task, const sym::SymmetrySpec& spec);

  int numJoints() const { return n_; }
  double timestep() const { return model_->opt.timestep; }
  // The state message of the present physics state at simulated time sim_t (utime left to the caller).
  void fillState(masa::lcmt_robot_state& state, const StateFaults& faults, double sim_t) const;
  // The command's PD law into the actuators' controls, then one physics step.
  void step(const masa::lcmt_robot_command& command);
  // Positions of the bodies for the state (mj_step leaves them one step behind).
  void updateKinematics();
  std::vector<double> jointAngles() const;

 private:
  task::Task& task_;
  const mjModel* model_;
  mjData* data_;
  int n_;
  std::vector<int> qpos_adr_, qvel_adr_, actuator_;
  std::vector<double> driver_gear_;  // torque to control: the nominal gear, whatever the perturbation drew
  int base_qpos_ = -1, base_qvel_ = -1;  // the robot-base free joint's, if the task has one
};

}  // namespace masa::deploy
