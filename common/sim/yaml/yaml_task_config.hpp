// The description of a task written in YAML (the `env` section of a task config whose
// task_code is `yaml`, docs/yaml_task.md): where each observation entry of the spec comes from,
// the reward terms, the terminations, the reference pose, the actuation, the reset and the heading
// to walk towards. Read and checked
// here for its own shape (unknown keys, wrong types, names per limb); the names are checked against
// the model and the kinds against the spec where the task resolves them (yaml_observation.hpp).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/sim/env_params.hpp"

namespace masa::task {

enum class ObsSource {
  kJointPos,     // the joint an action drives: angle (rad) or slide (m)
  kJointVel,
  kLastAction,   // the clamped action of the last step
  kBodyPos,      // a body's world position (any body)
  kBodyLinVel,   // world linear velocity of a body with a free joint
  kBodyAngVel,   // its angular velocity, world frame (or the free joint's own body frame)
  kBodyQuatW,    // w of its orientation quaternion, sign chosen so that w >= 0
  kBodyQuatXyz,  // (x, y, z) of the same quaternion
  kBodyAxis,     // one of its local axes in the world (an "up" vector)
  kBodyEuler,    // roll, pitch or yaw (ZYX) of its orientation
  kHeading,      // the direction the task asks to walk (task state, see HeadingConfig)
  kSensor,       // a MuJoCo sensor's values, as the model computes them
};

struct ObservationSourceConfig {
  std::string entry;    // the spec's observation entry it fills
  std::string path;     // its key path, for errors: "env.observation.limb.hip_pos"
  std::string file;     // where it was written
  ObsSource source = ObsSource::kJointPos;
  std::string name_key;            // which name it was given by: action, joint, body, sensor ("" for heading)
  std::vector<std::string> names;  // central: one name; limb: one per limb (a "{limb}" template expanded)
  std::vector<int> components{0, 1, 2};  // x, y, z of a vector source
  int axis = 2;                    // body_axis: the local axis; body_euler: 0 roll, 1 pitch, 2 yaw
  bool body_frame = false;         // body_ang_vel in the free joint's body frame
  bool from_pose = false;          // joint_pos: the offset from the reference pose
  std::string above_geom;          // body_pos z: the height above the top of this world geom
};

enum class RewardType { kAlive, kForwardVelocity, kHeading, kUpright, kLateralVelocity, kActionSquared, kEnergy };

struct RewardTermConfig {
  std::string name, path, file;
  RewardType type = RewardType::kAlive;
  std::string body;             // the body it measures (velocity and orientation terms)
  int axis = 0;                 // heading: local axis towards the heading; upright: local up axis
  bool has_target = false;      // forward_velocity: exp(-|v - target|) instead of v
  double target = 0.0;
  bool has_threshold = false;   // upright: 1 when the axis' world z exceeds it, else 0
  double threshold = 0.0;
};

enum class TerminationType { kHeight, kUpright };

struct TerminationConfig {
  std::string name, path, file;
  TerminationType type = TerminationType::kHeight;
  std::string body;
  std::string above;       // height: measured above this body's height ...
  std::string above_geom;  // ... or above the top of this world geom ("" for both: above z = 0)
  int axis = 2;       // upright: the local axis whose world z is tested
  double min = 0.0;   // the episode ends when the measure drops below it
};

struct PoseJointConfig {
  std::string name, path, file;  // an action entry (every limb's for a limb entry) or a joint
  double value = 0.0;
};

// How actions become controls: the actuators' ctrlrange, or a PD loop around the pose.
struct ActuationConfig {
  bool pd = false;
  double kp = 0.0, kd = 0.0;   // N m / rad, N m s / rad; torques clamped to each actuator's ctrlrange
  double action_scale = 0.0;   // target offset from the pose per unit action (rad)
  std::string file;            // where it was written
};

// A noise of 0 draws nothing. Draw order: per actuated joint (action order) its position, then its
// velocity; then every degree of freedom's velocity; then the heading.
struct ResetConfig {
  double joint_noise = 0.0;           // uniform +- on each actuated joint's position, kept inside its range
  double joint_velocity_noise = 0.0;  // uniform +- on each actuated joint's velocity
  double velocity_noise = 0.0;        // uniform +- on every degree of freedom's velocity
  // rest_on: the robot base is moved up or down so that the lowest of `feet` (geoms, their bounding
  // sphere) stands `clearance` above the top of the world geom `support`.
  std::string support;
  std::vector<std::string> feet;
  double clearance = 0.0;
  std::string path, file;
};

struct HeadingConfig {
  Eigen::Vector3d direction{1.0, 0.0, 0.0};  // horizontal unit vector
  bool random_yaw = false;                   // a uniform yaw drawn at every reset
};

struct YamlTaskConfig {
  std::string observation_file;  // where env.observation was written
  std::vector<ObservationSourceConfig> central, limb;  // in the config's order; keyed by spec entry
  std::vector<RewardTermConfig> reward;
  std::vector<TerminationConfig> termination;
  std::vector<PoseJointConfig> pose;  // the reference pose; other joints keep the model's qpos0
  ActuationConfig actuation;
  ResetConfig reset;
  HeadingConfig heading;
};

// Reads env.observation, env.reward, env.termination, env.pose, env.actuation, env.reset and
// env.heading (each marked as read in `params`). `num_limbs` expands "{limb}" name templates. Throws ConfigError naming the
// file and key path.
YamlTaskConfig readYamlTaskConfig(EnvParams& params, int num_limbs);

}  // namespace masa::task
