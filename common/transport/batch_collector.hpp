// Gathers validated chunks into training batches of a fixed number of environments, by policy
// version: an environment may enter a batch only if the parameters it acted with are at most
// max_policy_lag versions behind the learner (0 = strictly on-policy). Staler environments are
// evicted when the learner's version advances, and counted.
//
// Storage is a pool of environment slots allocated once (capacity_envs); chunks are copied in as
// they arrive, and take() writes a batch in the step-major ActorRollout layout.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/transport/actor_rollout.hpp"
#include "common/transport/rollout_assembler.hpp"

namespace masa::transport {

struct CollectorConfig {
  int num_envs = 0;  // environments per batch (ppo.num_envs)
  int horizon = 0;
  int obs_dim = 0;
  int act_dim = 0;
  int max_policy_lag = 0;
  int capacity_envs = 0;                // slots; 0 = 2 * num_envs
  std::vector<std::string> term_names;  // the task's reward terms, for episode statistics
};

struct CollectorStats {
  int64_t envs_added = 0;     // environments copied into the pool
  int64_t envs_stale = 0;     // dropped because their version fell behind current - lag
  int64_t envs_overflow = 0;  // dropped because the pool was full
  int64_t batches = 0;        // batches handed out
};

// A training batch: num_envs environments x T steps, plus where each environment came from.
struct RolloutBatch {
  ActorRollout data;                 // episodes and truncations renumbered to batch env indices
  std::vector<float> env_log_std;    // num_envs x act_dim: behaviour log std of each environment
  std::vector<int64_t> env_version;  // policy version each environment acted with
  std::vector<int32_t> env_actor;    // actor id
  std::vector<int32_t> env_index;    // environment index within its actor
};

class BatchCollector {
 public:
  explicit BatchCollector(const CollectorConfig& config);

  // Evicts environments older than version - max_policy_lag.
  void setLearnerVersion(int64_t version);
  int64_t learnerVersion() const { return version_; }

  // Copies the chunk's environments into free slots (dropping them if already stale).
  void add(const ValidatedChunk& chunk);

  int bufferedEnvs() const { return used_; }
  bool ready() const { return used_ >= cfg_.num_envs; }
  // When ready, fills `out` with num_envs environments, oldest version first (then arrival
  // order), frees their slots and returns true; otherwise returns false and leaves `out` alone.
  bool take(RolloutBatch& out);

  const CollectorStats& stats() const { return stats_; }
  const CollectorConfig& config() const { return cfg_; }

 private:
  int freeSlotFor(int64_t version);  // -1 when full of environments at least as new
  void release(int slot);

  struct Final {
    int t;
    std::vector<float> obs;
  };
  struct Episode {
    float ret;
    int32_t length;
    int8_t success;
    std::vector<float> term_sums;
  };

  CollectorConfig cfg_;
  int capacity_ = 0;
  int64_t version_ = 0;
  int used_ = 0;
  uint64_t arrivals_ = 0;
  CollectorStats stats_;

  // Slot s owns rows [s * rows, (s + 1) * rows) of each pool, environment-major.
  std::vector<float> obs_, actions_, mean_, log_prob_, reward_, log_std_;
  std::vector<int8_t> terminated_, truncated_;
  std::vector<char> in_use_;
  std::vector<int64_t> slot_version_;
  std::vector<uint64_t> slot_arrival_;
  std::vector<int32_t> slot_actor_, slot_env_;
  std::vector<std::vector<Final>> finals_;
  std::vector<int> num_finals_;
  std::vector<std::vector<Episode>> episodes_;
  std::vector<int> num_episodes_;
  std::vector<int> free_, order_;
  std::vector<int> chunk_slots_;  // slot of each environment of the chunk being added (-1: none)
  std::vector<std::pair<int32_t, const float*>> batch_finals_;
};

}  // namespace masa::transport
