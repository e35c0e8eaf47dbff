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
  const auto it = table().find(name);
  if (it == table().end()) {
    std::string known;
    for (const auto& n : registeredTasks()) known += (known.empty() ? "" : ", ") + n;
    throw std::runtime_error("unknown task '" + name + "' (known: " + known + ")");
  }
  make_ = it->second.make;
  EnvParams probe(env_, origin_, default_origin_);
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
  return make_(model_, spec_, params);
}

}  // namespace masa::task
