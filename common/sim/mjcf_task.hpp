// "mjcf": a task with no task code of its own, for checking the symmetry of a robot a user brings
// (an MJCF file and a spec with a `mujoco` section); see mjcf_task.cpp.
#pragma once

#include <memory>

#include "common/sim/task.hpp"

namespace masa::task {

std::unique_ptr<Task> makeMjcf(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec, EnvParams& params);

}  // namespace masa::task
