#include "common/task/registry.hpp"

#include <cstdlib>
#include <stdexcept>

#include "common/core/config_error.hpp"
#include "tasks/tasks.hpp"

namespace masa::task {
namespace {

// tasks/tasks.cpp's list, and what tests add with registerTask.
std::map<std::string, TaskInfo>& table() {
  static std::map<std::string, TaskInfo> t = [] {
    std::map<std::string, TaskInfo> listed;
    for (const TaskInfo& info : taskList())
      if (!listed.emplace(info.name, info).second) throw std::logic_error("task '" + info.name + "' listed twice");
    return listed;
  }();
  return t;
}

std::string sourceRoot() {
  if (const char* env = std::getenv("MASA_ROOT")) return env;
  return MASA_SOURCE_DIR;
}

}  // namespace

bool registerTask(TaskInfo info) {
  const std::string name = info.name;
  if (!table().emplace(name, std::move(info)).second)
    throw std::logic_error("task '" + name + "' registered twice");
  return true;
}

std::vector<std::string> registeredTasks() {
  std::vector<std::string> names;
  for (const auto& [n, info] : table()) names.push_back(n);
  return names;
}

TaskFactory::TaskFactory(const std::string& name, const sym::SymmetrySpec& spec, const YAML::Node& env,
                         const std::map<std::string, std::string>& origin, const std::string& default_origin)
    : name_(name), spec_(spec), env_(YAML::Clone(env)), origin_(origin), default_origin_(default_origin) {
  EnvParams probe(env_, origin_, default_origin_);
  const std::string code = probe.text("task_code", name);
  const auto it = table().find(code);
  if (it == table().end()) {
    std::string known;
    for (const auto& n : registeredTasks()) known += (known.empty() ? "" : ", ") + n;
    const std::string what = "unknown task '" + code + "' (known: " + known + ")";
    if (code != name) throw ConfigError(probe.origin("task_code"), "env.task_code", what);
    throw std::runtime_error(what + "; a task described in YAML sets env.task_code: yaml");
  }
  make_ = it->second.make;
  std::string file = probe.text("model_file", it->second.model_file);
  if (file.empty()) throw ConfigError(default_origin_, "env.model_file", "task '" + name + "' needs a model file");
  if (!file.empty() && file[0] != '/') file = sourceRoot() + "/" + file;
  model_ = MujocoModel::load(file);
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
