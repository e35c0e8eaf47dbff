// Builds tasks by name. Each task registers itself from its own folder (tasks/<name>/) with
// MASA_REGISTER_TASK; a TaskFactory then loads the model once and creates any number of
// environments that share it.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/task/task.hpp"

namespace masa::task {

using TaskMaker =
    std::function<std::unique_ptr<Task>(std::shared_ptr<const MujocoModel>, const sym::SymmetrySpec&, EnvParams&)>;

struct TaskInfo {
  std::string name;
  std::string model_file;  // relative to the source tree, e.g. "tasks/a1_beam/model.xml"
  TaskMaker make;
};

bool registerTask(TaskInfo info);
std::vector<std::string> registeredTasks();

class TaskFactory {
 public:
  // Loads the model (env.model_file overrides the registered path) and validates the env section
  // by building one task; throws std::runtime_error or ConfigError naming what is wrong.
  TaskFactory(const std::string& name, const sym::SymmetrySpec& spec, const YAML::Node& env,
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

#define MASA_TASK_CONCAT_(a, b) a##b
#define MASA_TASK_CONCAT(a, b) MASA_TASK_CONCAT_(a, b)
// MASA_REGISTER_TASK("a1_beam", "tasks/a1_beam/model.xml", makerFunction)
#define MASA_REGISTER_TASK(name, model_file, maker) \
  static const bool MASA_TASK_CONCAT(masa_task_registered_, __LINE__) = ::masa::task::registerTask({name, model_file, maker})
