// Builds tasks by name from a catalog the program passes in (the shipped one is tasks::catalog() in
// tasks/tasks.cpp): the simulation layer never sees the task list. A TaskFactory loads the model
// once and creates any number of environments that share it.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/sim/task.hpp"

namespace masa::task {

using TaskMaker =
    std::function<std::unique_ptr<Task>(std::shared_ptr<const MujocoModel>, const sym::SymmetrySpec&, EnvParams&)>;

struct TaskInfo {
  std::string name;
  std::string model_file;  // relative to the source tree, e.g. "tasks/a1_beam/model.xml"
  TaskMaker make;
};

// The tasks a program knows, by name. A name listed twice is an error (std::logic_error).
class TaskCatalog {
 public:
  TaskCatalog() = default;
  explicit TaskCatalog(const std::vector<TaskInfo>& tasks);

  // Adds a task beyond the list (tests add their own fixtures); a name taken already is an error.
  void add(TaskInfo info);
  const TaskInfo* find(const std::string& name) const;
  std::vector<std::string> names() const;  // sorted

 private:
  std::map<std::string, TaskInfo> tasks_;
};

class TaskFactory {
 public:
  // Loads the model (env.model_file overrides the registered path) and validates the env section
  // by building one task; throws std::runtime_error or ConfigError naming what is wrong. The code
  // that runs is the listed task called env.task_code when given, else `name`: a config of its
  // own name can run another task's code, e.g. `task_code: yaml` for a task written in YAML.
  TaskFactory(const TaskCatalog& catalog, const std::string& name, const sym::SymmetrySpec& spec, const YAML::Node& env,
              const std::map<std::string, std::string>& origin = {}, const std::string& default_origin = "configs");

  std::unique_ptr<Task> create() const;
  const std::shared_ptr<const MujocoModel>& model() const { return model_; }
  const std::string& name() const { return name_; }

 private:
  std::string name_;
  sym::SymmetrySpec spec_;
  YAML::Node env_;
  std::map<std::string, std::string> origin_;
  std::string default_origin_;
  TaskMaker make_;
  std::shared_ptr<const MujocoModel> model_;
};

}  // namespace masa::task
