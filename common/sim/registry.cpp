#include "common/sim/registry.hpp"

#include <cstdlib>
#include <stdexcept>

#include "common/core/config_error.hpp"
#include "common/core/env_directory.hpp"

namespace masa::task {
namespace {

std::string sourceRoot() {
  return directoryFromEnvironment("MASA_ROOT", MASA_SOURCE_DIR);
}

}  // namespace

TaskCatalog::TaskCatalog(const std::vector<TaskInfo>& tasks) {
  for (const TaskInfo& info : tasks) add(info);
}

void TaskCatalog::add(TaskInfo info) {
  const std::string name = info.name;
  if (!tasks_.emplace(name, std::move(info)).second) throw std::logic_error("task '" + name + "' listed twice");
}

const TaskInfo* TaskCatalog::find(const std::string& name) const {
  const auto it = tasks_.find(name);
  return it == tasks_.end() ? nullptr : &it->second;
}

std::vector<std::string> TaskCatalog::names() const {
  std::vector<std::string> names;
  for (const auto& [n, info] : tasks_) names.push_back(n);
  return names;
}

TaskFactory::TaskFactory(const TaskCatalog& catalog, const std::string& name, const sym::SymmetrySpec& spec, const YAML::Node& env,
                         const std::map<std::string, std::string>& origin, const std::string& default_origin)
    : name_(name), spec_(spec), env_(YAML::Clone(env)), origin_(origin), default_origin_(default_origin) {
  EnvParams probe(env_, origin_, default_origin_);
  const std::string code = probe.text("task_code", name);
  const TaskInfo* info = catalog.find(code);
  if (info == nullptr) {
    std::string known;
    for (const auto& n : catalog.names()) known += (known.empty() ? "" : ", ") + n;
    const std::string what = "unknown task '" + code + "' (known: " + known + ")";
    if (code != name) throw ConfigError(probe.origin("task_code"), "env.task_code", what);
    throw std::runtime_error(what + "; a task described in YAML sets env.task_code: yaml");
  }
  make_ = info->make;
  std::string file = probe.text("model_file", info->model_file);
  // Errors name the file that chose the task code (a YAML task's file) or the model, not "configs".
  if (file.empty()) throw ConfigError(probe.origin("task_code"), "env.model_file", "task '" + name + "' needs a model file");
  if (file[0] != '/') file = sourceRoot() + "/" + file;
  try {
    model_ = MujocoModel::load(file);
  } catch (const std::exception& e) {
    throw ConfigError(probe.origin("model_file"), "env.model_file", e.what());
  }
  // Building one task validates every parameter (and the spec's actuator names) up front.
  std::unique_ptr<Task> t = make_(model_, spec_, probe);
  probe.finish();
}

std::unique_ptr<Task> TaskFactory::create() const {
  EnvParams params(env_, origin_, default_origin_);
  params.text("model_file", "");
  params.text("task_code", "");
  return make_(model_, spec_, params);
}

}  // namespace masa::task
