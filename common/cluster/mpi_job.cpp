#include "common/cluster/mpi_job.hpp"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include <unistd.h>

#ifdef MASA_HAVE_MPI
#include <mpi.h>
#endif

namespace masa::cluster {

bool builtWithMpi() {
#ifdef MASA_HAVE_MPI
  return true;
#else
  return false;
#endif
}

bool launchedByMpi(bool built_with_mpi) {
  bool launched = false;
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"})
    if (std::getenv(var) != nullptr) launched = true;
  if (!launched || built_with_mpi) return launched;
  // Without MPI every process of the job would think itself alone: two learners on one URL.
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "SLURM_STEP_NUM_TASKS", "PMI_SIZE"}) {
    const char* size = std::getenv(var);
    if (size != nullptr) {
      if (std::string(size) == "1") return false;  // a job of one process: alone indeed
      break;
    }
  }
  throw std::runtime_error(
      "started by mpirun or srun as one process of a job, but this build has no MPI: install libopenmpi-dev "
      "(bash scripts/install_deps.sh) and build again, or start the processes without mpirun (deploy/train.sh)");
}

bool launchedByMpi() { return launchedByMpi(builtWithMpi()); }

#ifdef MASA_HAVE_MPI

namespace {

void check(int rc, const char* what) {
  if (rc == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(rc, text, &len);
  throw std::runtime_error(std::string(what) + ": " + std::string(text, static_cast<std::size_t>(len)));
}

class MpiCommunicator final : public Communicator {
 public:
  explicit MpiCommunicator(MPI_Comm comm) : comm_(comm) {
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void sum(double* x, int n) override {
    if (n > 0) check(MPI_Allreduce(MPI_IN_PLACE, x, n, MPI_DOUBLE, MPI_SUM, comm_), "MPI_Allreduce");
  }
  void sum(float* x, int n) override {
    if (n > 0) check(MPI_Allreduce(MPI_IN_PLACE, x, n, MPI_FLOAT, MPI_SUM, comm_), "MPI_Allreduce");
  }
  std::vector<int64_t> gather(int64_t x) override {
    std::vector<int64_t> all(static_cast<std::size_t>(size_));
    check(MPI_Allgather(&x, 1, MPI_INT64_T, all.data(), 1, MPI_INT64_T, comm_), "MPI_Allgather");
    return all;
  }
  void broadcast(std::vector<uint8_t>& bytes, int root) override {
    int64_t n = static_cast<int64_t>(bytes.size());
    check(MPI_Bcast(&n, 1, MPI_INT64_T, root, comm_), "MPI_Bcast");
    bytes.resize(static_cast<std::size_t>(n));
    // In pieces below INT_MAX bytes (MPI counts are int).
    constexpr int64_t kPiece = 1 << 30;
    for (int64_t off = 0; off < n; off += kPiece)
      check(MPI_Bcast(bytes.data() + off, static_cast<int>(std::min(kPiece, n - off)), MPI_BYTE, root, comm_),
            "MPI_Bcast");
  }
  void beginBarrier() override {
    if (pending_) throw std::logic_error("beginBarrier: the previous barrier has not completed");
    check(MPI_Ibarrier(comm_, &barrier_), "MPI_Ibarrier");
    pending_ = true;
  }
  bool barrierDone() override {
    if (!pending_) throw std::logic_error("barrierDone: no barrier begun");
    int done = 0;
    check(MPI_Test(&barrier_, &done, MPI_STATUS_IGNORE), "MPI_Test");
    if (done) pending_ = false;
    return done != 0;
  }

 private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  MPI_Request barrier_ = MPI_REQUEST_NULL;
  bool pending_ = false;
};

}  // namespace

struct MpiJob::Impl {
  MPI_Comm role_comm = MPI_COMM_NULL;
  MPI_Comm done_comm = MPI_COMM_NULL;  // a duplicate of the world, for the end-of-training barrier
  MPI_Request done = MPI_REQUEST_NULL;
  bool done_begun = false, done_seen = false;
  int learner_zero_world_rank = 0;
  std::unique_ptr<MpiCommunicator> learners;
};

MpiJob::MpiJob(Role role) : impl_(std::make_unique<Impl>()), role_(role) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) throw std::logic_error("MpiJob: MPI is already initialized (one MpiJob per process)");
  int provided = 0;
  // Serialized: an actor polls trainingFinished() from a watcher thread while its main thread acts.
  check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided), "MPI_Init_thread");
  if (provided < MPI_THREAD_SERIALIZED) throw std::runtime_error("this MPI does not allow MPI calls from a second thread (MPI_THREAD_SERIALIZED)");
  // Errors come back as codes (and become exceptions here) instead of aborting inside MPI.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &world_rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &world_size_);
  std::vector<int> roles(static_cast<std::size_t>(world_size_));
  const int mine = static_cast<int>(role);
  check(MPI_Allgather(&mine, 1, MPI_INT, roles.data(), 1, MPI_INT, MPI_COMM_WORLD), "MPI_Allgather");
  learner_count_ = 0;
  impl_->learner_zero_world_rank = -1;
  for (int r = 0; r < world_size_; ++r) {
    if (roles[static_cast<std::size_t>(r)] != static_cast<int>(Role::kLearner)) continue;
    if (impl_->learner_zero_world_rank < 0) impl_->learner_zero_world_rank = r;
    ++learner_count_;
  }
  if (learner_count_ == 0) throw std::runtime_error("MPI job without a learner: start masa_learner as one of its programs");
  check(MPI_Comm_split(MPI_COMM_WORLD, mine, world_rank_, &impl_->role_comm), "MPI_Comm_split");
  MPI_Comm_set_errhandler(impl_->role_comm, MPI_ERRORS_RETURN);
  MPI_Comm_rank(impl_->role_comm, &role_index_);
  check(MPI_Comm_dup(MPI_COMM_WORLD, &impl_->done_comm), "MPI_Comm_dup");
  if (role == Role::kLearner) impl_->learners = std::make_unique<MpiCommunicator>(impl_->role_comm);
}

MpiJob::~MpiJob() {
  impl_->learners.reset();
  if (role_ == Role::kActor && impl_->done_begun && !impl_->done_seen) {
    // Stopped before the learners said training is over (a signal: scancel, Ctrl-C of mpirun).
    // The learners say it as they stop; if they do not within seconds they are gone, and
    // MPI_Finalize would wait for them forever: leave without it (the launcher is ending the job).
    for (int i = 0; i < 100 && !impl_->done_seen; ++i) {
      int flag = 0;
      if (MPI_Test(&impl_->done, &flag, MPI_STATUS_IGNORE) != MPI_SUCCESS) break;
      impl_->done_seen = flag != 0;
      if (!impl_->done_seen) usleep(50000);
    }
    if (!impl_->done_seen) return;
  }
  MPI_Finalize();
}

Communicator& MpiJob::learners() {
  if (!impl_->learners) throw std::logic_error("MpiJob::learners: this process is an actor");
  return *impl_->learners;
}

void MpiJob::shareFromLearnerZero(std::vector<uint8_t>& bytes) {
  int64_t n = static_cast<int64_t>(bytes.size());
  const int root = impl_->learner_zero_world_rank;
  check(MPI_Bcast(&n, 1, MPI_INT64_T, root, MPI_COMM_WORLD), "MPI_Bcast");
  bytes.resize(static_cast<std::size_t>(n));
  if (n > 0) check(MPI_Bcast(bytes.data(), static_cast<int>(n), MPI_BYTE, root, MPI_COMM_WORLD), "MPI_Bcast");
}

std::vector<uint8_t> MpiJob::gatherFromEveryProcess(const std::vector<uint8_t>& mine) {
  const int64_t n = static_cast<int64_t>(mine.size());
  std::vector<int64_t> sizes(static_cast<std::size_t>(world_size_));
  check(MPI_Allgather(&n, 1, MPI_INT64_T, sizes.data(), 1, MPI_INT64_T, MPI_COMM_WORLD), "MPI_Allgather");
  // Every process sees every size, so all of them throw alike (none waits in the gather below).
  if (std::any_of(sizes.begin(), sizes.end(), [&](int64_t s) { return s != n; })) {
    std::string each;
    for (int r = 0; r < world_size_; ++r)
      each += (r ? ", process " : "process ") + std::to_string(r) + ": " + std::to_string(sizes[static_cast<std::size_t>(r)]);
    throw std::runtime_error("gatherFromEveryProcess: the processes give unequal byte counts (" + each + ")");
  }
  std::vector<uint8_t> all(mine.size() * static_cast<std::size_t>(world_size_));
  if (n > 0)
    check(MPI_Allgather(mine.data(), static_cast<int>(n), MPI_BYTE, all.data(), static_cast<int>(n), MPI_BYTE,
                        MPI_COMM_WORLD),
          "MPI_Allgather");
  return all;
}

void MpiJob::finishTraining() {
  if (role_ != Role::kLearner) throw std::logic_error("finishTraining: only learner ranks end training");
  if (impl_->done_seen) return;
  check(MPI_Ibarrier(impl_->done_comm, &impl_->done), "MPI_Ibarrier");
  impl_->done_begun = true;
  check(MPI_Wait(&impl_->done, MPI_STATUS_IGNORE), "MPI_Wait");
  impl_->done_seen = true;
}

bool MpiJob::trainingFinished() {
  if (impl_->done_seen) return true;
  if (!impl_->done_begun) {
    // An actor enters the barrier at once and learns that it completed when the learners enter it.
    if (role_ == Role::kLearner) return false;
    check(MPI_Ibarrier(impl_->done_comm, &impl_->done), "MPI_Ibarrier");
    impl_->done_begun = true;
  }
  int flag = 0;
  check(MPI_Test(&impl_->done, &flag, MPI_STATUS_IGNORE), "MPI_Test");
  impl_->done_seen = flag != 0;
  return impl_->done_seen;
}

void MpiJob::abort(int code) {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::_Exit(code);
}

#else  // no MPI in this build

struct MpiJob::Impl {};

MpiJob::MpiJob(Role role) : role_(role) {
  throw std::runtime_error("this masa was built without MPI (install libopenmpi-dev and rebuild)");
}
MpiJob::~MpiJob() = default;
Communicator& MpiJob::learners() { return soloCommunicator(); }
void MpiJob::shareFromLearnerZero(std::vector<uint8_t>&) {}
std::vector<uint8_t> MpiJob::gatherFromEveryProcess(const std::vector<uint8_t>& mine) { return mine; }
void MpiJob::finishTraining() {}
bool MpiJob::trainingFinished() { return false; }
void MpiJob::abort(int code) { std::_Exit(code); }

#endif

}  // namespace masa::cluster
