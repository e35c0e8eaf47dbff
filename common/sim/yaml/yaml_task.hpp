// "yaml": a task described by its config's env section instead of code (docs/yaml_task.md).
#pragma once

#include <memory>

#include "common/sim/task.hpp"

namespace masa::task {

std::unique_ptr<Task> makeYamlTask(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec,
                                   EnvParams& params);

}  // namespace masa::task
