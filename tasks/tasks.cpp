#include "tasks/tasks.hpp"

namespace masa::task {

// The one list of tasks: name, model file (relative to the source tree), maker.
const std::vector<TaskInfo>& taskList() {
  static const std::vector<TaskInfo> list = {
      {"mjcf", "", &makeMjcf},  // no model of its own: env.model_file names the user's MJCF
      {"yaml", "", &makeYamlTask},  // a config's env section describes the task (env.task_code: yaml)
      {"a1_beam", "tasks/a1_beam/model.xml", &makeA1Beam},
      {"ant_acrobatic", "tasks/ant_acrobatic/model.xml", &makeAntAcrobatic},
      {"humanoid_dribbling", "tasks/humanoid_dribbling/model.xml", &makeHumanoidDribbling},
      {"humanoid_tightrope", "tasks/humanoid_tightrope/model.xml", &makeHumanoidTightrope},
      {"trifinger_lift", "tasks/trifinger_lift/model.xml", &makeTrifingerLift},
  };
  return list;
}

TaskCatalog& taskCatalog() {
  static TaskCatalog catalog(taskList());
  return catalog;
}

}  // namespace masa::task
