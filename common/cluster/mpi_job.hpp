// A process of a job that mpirun or srun started (MPMD: learner ranks and actors as the ranks of one
// job). Every process of such a job must initialize MPI, or the others hang in MPI_Init; so the
// actors do too, and then use MPI only to learn their place and to hear that training is over.
//
// Construction is collective over the whole job (every learner and every actor): MPI_Init, then
// every process says its role, so that each knows the learner ranks (the learners' world ranks,
// in order) and its own index among the processes of its role. The learners get a Communicator
// over the learner ranks alone. Destruction finalizes MPI.
//
// Built only with MPI (MASA_HAVE_MPI); launchedByMpi() is always there and false without it.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "common/cluster/communicator.hpp"

namespace masa::cluster {

enum class Role : int { kLearner = 0, kActor = 1 };

// True when the environment says this process is a rank of an MPI launch (mpirun's
// OMPI_COMM_WORLD_SIZE, or PMIx/PMI ranks as srun --mpi=pmix sets them) and this build has MPI.
// A build without MPI started as one of several processes of such a launch throws (each process
// would take itself for the only learner), saying what to install.
bool launchedByMpi();
bool launchedByMpi(bool built_with_mpi);  // the same, for this build or one without MPI (tests)
bool builtWithMpi();

class MpiJob {
 public:
  explicit MpiJob(Role role);
  ~MpiJob();
  MpiJob(const MpiJob&) = delete;
  MpiJob& operator=(const MpiJob&) = delete;

  int worldRank() const { return world_rank_; }
  int worldSize() const { return world_size_; }
  Role role() const { return role_; }
  // This process's index among the processes of its role (learner rank, or actor index), and their number.
  int roleIndex() const { return role_index_; }
  int learnerCount() const { return learner_count_; }
  int actorCount() const { return world_size_ - learner_count_; }

  // The learner ranks (learners only; throws for an actor).
  Communicator& learners();

  // Collective over the whole job: learner rank 0's bytes to every process (the run's plan: key,
  // run id, channels). Call it once, at the same point of every process's start.
  void shareFromLearnerZero(std::vector<uint8_t>& bytes);
  // Collective over the whole job: every process's bytes, concatenated in world-rank order (a
  // signed job's public keys, job_roster.hpp). Every process must give as many bytes; throws
  // std::runtime_error naming the sizes otherwise.
  std::vector<uint8_t> gatherFromEveryProcess(const std::vector<uint8_t>& mine);

  // Training is over. Learners: say so (every learner rank must call it; returns once all have).
  // Actors: poll it in their loop (true once every learner rank has said it).
  void finishTraining();
  bool trainingFinished();

  // Ends every process of the job (MPI_Abort): for a process that fails where the others would
  // wait for it in a collective. Does not return.
  [[noreturn]] void abort(int code);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Role role_;
  int world_rank_ = 0, world_size_ = 1, role_index_ = 0, learner_count_ = 1;
};

}  // namespace masa::cluster
