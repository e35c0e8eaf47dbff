// Every task masa knows, as one list (tasks.cpp): a task is its folder (tasks/<name>/), its maker
// declared here, and one line in taskList(). Nothing registers itself.
#pragma once

#include <vector>

#include "common/task/registry.hpp"

namespace masa::task {

// The makers, one per task folder, and the two tasks without code of their own: "mjcf" (a model
// alone, common/task/mjcf_task.cpp) and "yaml" (a task described by its config, common/task/yaml_task.cpp).
std::unique_ptr<Task> makeMjcf(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec, EnvParams& params);
std::unique_ptr<Task> makeYamlTask(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec,
                                   EnvParams& params);
std::unique_ptr<Task> makeA1Beam(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec, EnvParams& params);
std::unique_ptr<Task> makeAntAcrobatic(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec,
                                       EnvParams& params);
std::unique_ptr<Task> makeHumanoidDribbling(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec,
                                            EnvParams& params);
std::unique_ptr<Task> makeHumanoidTightrope(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec,
                                            EnvParams& params);
std::unique_ptr<Task> makeTrifingerLift(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec,
                                        EnvParams& params);

// The tasks, in the order `masa_verify`, the benchmarks and error messages list them.
const std::vector<TaskInfo>& taskList();

}  // namespace masa::task
