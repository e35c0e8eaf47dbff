// launchedByMpi: what a process concludes from the launcher's environment (no MPI needed). A build
// without MPI started as one of several processes of an mpirun or srun job must refuse: each
// process would take itself for the only learner (docs/inputs.md gap 17).
#include <gtest/gtest.h>

#include <cstdlib>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/cluster/mpi_job.hpp"

namespace {

using Vars = std::map<std::string, std::string>;

const char* const kJobVariables[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "SLURM_STEP_NUM_TASKS",
                                     "PMI_SIZE"};

// Sets exactly `vars` among the job variables for the test's lifetime, restoring the old values.
class JobEnvironment {
 public:
  explicit JobEnvironment(const Vars& vars) {
    for (const char* name : kJobVariables) {
      const char* old = std::getenv(name);
      saved_[name] = old ? std::optional<std::string>(old) : std::nullopt;
      unsetenv(name);
    }
    for (const auto& [name, value] : vars) setenv(name.c_str(), value.c_str(), 1);
  }
  ~JobEnvironment() {
    for (const auto& [name, value] : saved_)
      if (value)
        setenv(name.c_str(), value->c_str(), 1);
      else
        unsetenv(name.c_str());
  }

 private:
  std::map<std::string, std::optional<std::string>> saved_;
};

using masa::cluster::launchedByMpi;

TEST(MpiLaunch, WithoutJobVariablesAProcessIsAloneInEitherBuild) {
  JobEnvironment env(Vars{});
  EXPECT_FALSE(launchedByMpi(false));
  EXPECT_FALSE(launchedByMpi(true));
}

TEST(MpiLaunch, AJobOfOneProcessRunsEvenWithoutMpi) {
  {
    JobEnvironment env(Vars{{"OMPI_COMM_WORLD_SIZE", "1"}});
    EXPECT_FALSE(launchedByMpi(false));
    EXPECT_TRUE(launchedByMpi(true));
  }
  {
    JobEnvironment env(Vars{{"PMI_RANK", "0"}, {"SLURM_STEP_NUM_TASKS", "1"}});
    EXPECT_FALSE(launchedByMpi(false));
  }
  {
    JobEnvironment env(Vars{{"PMIX_RANK", "0"}, {"PMI_SIZE", "1"}});
    EXPECT_FALSE(launchedByMpi(false));
  }
}

TEST(MpiLaunch, OneOfSeveralProcessesWithoutMpiRefusesSayingWhatToInstall) {
  for (const auto& vars : std::vector<Vars>{
           {{"OMPI_COMM_WORLD_SIZE", "3"}},
           {{"PMI_RANK", "1"}, {"SLURM_STEP_NUM_TASKS", "4"}},
           {{"PMIX_RANK", "2"}, {"PMI_SIZE", "8"}},
           {{"PMI_RANK", "0"}}}) {  // a rank without a size: not known to be alone
    JobEnvironment env(vars);
    try {
      launchedByMpi(false);
      ADD_FAILURE() << "a build without MPI took itself for the only process of " << vars.begin()->first << "="
                    << vars.begin()->second;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("libopenmpi-dev"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(launchedByMpi(true));
  }
}

}  // namespace
