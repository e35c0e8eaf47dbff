// One MPI job of learner ranks and actors (MPMD), as a cluster launch makes it:
//   mpirun -np 2 masa_test_mpi_job_roles learner : -np 3 masa_test_mpi_job_roles actor
// Every process learns the job's shape and its index among its role; learner rank 0's bytes reach
// every process, and every process's bytes every process (unequal sizes refused by name); actors
// see training going on until every learner rank has ended it, then see it over. Exit status 0
// everywhere and "PASS" from learner rank 0 when all of that holds.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "common/cluster/mpi_job.hpp"

int main(int argc, char** argv) {
  using namespace masa::cluster;
  if (argc != 2 || (std::strcmp(argv[1], "learner") != 0 && std::strcmp(argv[1], "actor") != 0)) {
    std::fprintf(stderr, "usage: %s learner|actor\n", argv[0]);
    return 2;
  }
  const bool learner = std::strcmp(argv[1], "learner") == 0;
  int failures = 0;
  auto expect = [&](bool ok, const std::string& what) {
    if (!ok) {
      ++failures;
      std::fprintf(stderr, "FAILED (%s): %s\n", argv[1], what.c_str());
    }
  };
  // A build without MPI, started as a process of this job, refuses: it would take itself for alone.
  expect(launchedByMpi(), "mpirun's environment is seen");
  try {
    launchedByMpi(false);
    expect(false, "a build without MPI in a job of 5 refuses to start");
  } catch (const std::runtime_error& e) {
    expect(std::string(e.what()).find("this build has no MPI") != std::string::npos, e.what());
  }
  MpiJob job(learner ? Role::kLearner : Role::kActor);
  expect(job.learnerCount() == 2 && job.actorCount() == 3, "2 learner ranks and 3 actors in a job of 5");
  expect(job.roleIndex() == (learner ? job.worldRank() : job.worldRank() - 2), "the index among the role follows the world rank");
  if (learner) expect(job.learners().size() == 2 && job.learners().rank() == job.roleIndex(), "the learners' communicator");

  std::vector<uint8_t> plan;
  if (learner && job.roleIndex() == 0) plan = {'r', 'u', 'n', 0, 255};
  job.shareFromLearnerZero(plan);
  expect(plan == std::vector<uint8_t>{'r', 'u', 'n', 0, 255}, "learner rank 0's bytes reach every process");

  // Every process's bytes, in world-rank order (a signed job's public keys, job_roster.hpp).
  const std::vector<uint8_t> all = job.gatherFromEveryProcess(
      {static_cast<uint8_t>(learner ? 'L' : 'A'), static_cast<uint8_t>(job.roleIndex())});
  expect(all == std::vector<uint8_t>{'L', 0, 'L', 1, 'A', 0, 'A', 1, 'A', 2},
         "every process's bytes reach every process in world-rank order");
  try {
    // Sizes that differ are named, not read past: here every process gives 1 byte but rank 0 2.
    job.gatherFromEveryProcess(std::vector<uint8_t>(job.worldRank() == 0 ? 2 : 1, 7));
    expect(false, "a gather of unequal sizes is refused");
  } catch (const std::runtime_error& e) {
    expect(std::string(e.what()).find("unequal byte counts (process 0: 2, process 1: 1, process 2: 1") !=
               std::string::npos,
           e.what());
  }

  if (learner) {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // "training"
    job.finishTraining();
  } else {
    int polls_before = 0;
    while (!job.trainingFinished()) {
      ++polls_before;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    expect(polls_before >= 5, "actors see training go on while the learners train");
  }
  if (learner && job.roleIndex() == 0 && failures == 0) std::printf("PASS\n");
  return failures == 0 ? 0 : 1;
}
