// A loaded MuJoCo model, shared read-only by every environment of a task (each env has its own
// mjData). Loading failures name the file and MuJoCo's reason.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <string>

namespace masa::task {

class MujocoModel {
 public:
  // Throws std::runtime_error "<path>: <reason>" when the file is missing or does not compile.
  static std::shared_ptr<MujocoModel> load(const std::string& path);
  ~MujocoModel();
  MujocoModel(const MujocoModel&) = delete;
  MujocoModel& operator=(const MujocoModel&) = delete;

  const mjModel* get() const { return m_; }
  mjModel* mutableModel() { return m_; }  // for tools that tighten solver options on their own copy
  const std::string& path() const { return path_; }

  // Index of a named object (mjOBJ_JOINT, mjOBJ_ACTUATOR, mjOBJ_BODY, ...); throws naming the
  // model file, the object type and the name when it does not exist.
  int id(int type, const std::string& name) const;

  std::shared_ptr<MujocoModel> clone() const;

 private:
  MujocoModel(mjModel* m, std::string path) : m_(m), path_(std::move(path)) {}
  mjModel* m_;
  std::string path_;
};

}  // namespace masa::task
