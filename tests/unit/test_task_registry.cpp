// The tasks are one list (tasks/tasks.cpp): every task folder is in it, and every program that
// links the task library once finds every task (no static self-registration to lose).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "tasks/tasks.hpp"

namespace masa::task {
namespace {

TEST(TaskRegistry, EveryTaskFolderIsInTheListAndTheListIsWhatTheRegistryKnows) {
  std::vector<std::string> folders;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(MASA_SOURCE_DIR) + "/tasks"))
    if (entry.is_directory() && std::filesystem::exists(entry.path() / "model.xml"))
      folders.push_back(entry.path().filename().string());
  ASSERT_EQ(folders.size(), 5u);
  const std::vector<std::string> known = taskCatalog().names();
  for (const std::string& f : folders)
    EXPECT_NE(std::find(known.begin(), known.end(), f), known.end()) << "tasks/" << f << " is not in tasks/tasks.cpp";
  for (const TaskInfo& info : taskList()) {
    EXPECT_NE(std::find(known.begin(), known.end(), info.name), known.end()) << info.name;
    if (!info.model_file.empty()) {
      EXPECT_EQ(info.model_file, "tasks/" + info.name + "/model.xml");
    }
  }
}

TEST(TaskRegistry, ANameTakenAlreadyCannotBeAddedAgain) {
  EXPECT_THROW(taskCatalog().add({"a1_beam", "tasks/a1_beam/model.xml", &makeA1Beam}), std::logic_error);
  EXPECT_THROW(TaskCatalog({{"x", "", &makeMjcf}, {"x", "", &makeYamlTask}}), std::logic_error);
}

// The simulation layer knows only the catalog it is given: a name outside it is refused and the
// error lists what the catalog holds.
TEST(TaskRegistry, AFactoryBuildsOnlyFromTheCatalogItIsGiven) {
  const TaskCatalog only_mjcf({{"mjcf", "", &makeMjcf}});
  try {
    TaskFactory(only_mjcf, "a1_beam", sym::SymmetrySpec{}, YAML::Node());
    FAIL() << "a1_beam is not in the catalog";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown task 'a1_beam' (known: mjcf)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace masa::task
