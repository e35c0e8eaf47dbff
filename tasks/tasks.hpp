// Every task masa ships, as one list (tasks.cpp): a task is its folder (tasks/<name>/), its maker
// declared here, and one line in taskList(). Nothing registers itself; the programs (actors,
// learner, deploy, tools) pass taskCatalog() to the simulation layer, which never sees this list.
#pragma once

#include <vector>

#include "common/sim/mjcf_task.hpp"
#include "common/sim/registry.hpp"
#include "common/sim/yaml/yaml_task.hpp"

namespace masa::task {

// The makers, one per task folder. The list also holds the two tasks without code of their own:
// "mjcf" (a model alone, common/sim/mjcf_task.hpp) and "yaml" (a task described by its config,
// common/sim/yaml/yaml_task.hpp).
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

// The list as the catalog every program builds its tasks from. Mutable only so that tests can add
// their fixtures (TaskCatalog::add); programs do not.
TaskCatalog& taskCatalog();

}  // namespace masa::task
