// The observation of a YAML task: each entry of the spec's observation layout filled from the
// source its config names (yaml_task_config.hpp), resolved once against the model and the spec.
//
// Resolution checks what a spec alone cannot: that every entry has a source and every source an
// entry, that the names exist in the model, that a source gives as many values as its entry holds,
// and that the entry's kind is how the source really transforms under the group (a world angular
// velocity is axial, a joint angle follows its action's kind, Euler angles are linear only under a
// mirror, ...), naming the kind that would be right. Sensors are taken at the spec's word: the
// physics verifier (masa_verify) checks them.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/sim/model_lookup.hpp"
#include "common/sim/task.hpp"
#include "common/sim/yaml/yaml_task_config.hpp"

namespace masa::task {

class YamlObservation {
 public:
  // `task` gives the model, the spec and which joint each action drives; `pose` is the reference
  // position of each action's joint (what `from_pose` observes from).
  YamlObservation(const YamlTaskConfig& config, const Task& task, const std::vector<double>& pose);

  // obsDim() values from the current state: poses must be fresh (mj_kinematics), and sensors too
  // when usesSensors() (mj_forward).
  void write(const mjData* d, const std::vector<double>& last_action, const Eigen::Vector3d& heading,
             float* out) const;
  bool usesSensors() const { return uses_sensors_; }

 private:
  struct Item {
    ObsSource source = ObsSource::kJointPos;
    int out = 0;                // first output index
    std::vector<int> actions;   // joint sources: the action indices, in the entry's order
    std::vector<int> qadr, dofadr;
    std::vector<double> joint_offset;  // joint_pos: subtracted (the pose, or 0)
    int body = -1;              // body_pos
    double height_offset = 0.0;  // body_pos z: subtracted (a geom's top, or 0)
    FreeBody free;              // free-body sources
    int sensor_adr = 0, sensor_dim = 0;
    std::vector<int> components;
    int axis = 2;
    bool body_frame = false;
  };

  struct Resolving;  // one entry's source being resolved for one limb (yaml_observation.cpp)
  void resolve(const ObservationSourceConfig& c, const sym::Entry& e, int limb, int out, const Task& task,
               const std::vector<double>& pose);
  void resolveActuated(const Resolving& r, const std::vector<double>& pose, Item& item);
  void resolveBody(const Resolving& r, Item& item);
  void resolveSensor(const Resolving& r, Item& item);

  std::vector<Item> items_;
  bool uses_sensors_ = false;
};

}  // namespace masa::task
