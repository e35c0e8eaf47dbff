// Gathers validated chunks into training batches of a fixed number of environments, by policy
// version: an environment may enter a batch only if the parameters it acted with are at most
// max_policy_lag versions behind the learner (0 = strictly on-policy). Staler environments are
// evicted when the learner's version advances, and counted.
//
// The pool is one rollout::Rollout of capacity_envs environments allocated once, in the layout of
// the chunks and of rollout::RolloutBuffer (step-major): each environment of a chunk is copied into a
// free slot (a column of the pool) as it arrives, and take() copies the chosen columns straight
// into the PPO buffer. Truncations and episodes are kept in the pool's own lists, indexed by slot.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/rollout/rollout.hpp"
#include "learner/intake/rollout_assembler.hpp"
#include "common/rollout/rollout_buffer.hpp"

namespace masa::learner {

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
  int64_t short_batches = 0;  // of them, short of environments that were lost (takeShort)
};

// Where each environment of a batch came from.
struct BatchOrigin {
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
  // When ready, fills `out` (num_envs x horizon, the collector's dimensions) with num_envs
  // environments, oldest version first (then arrival order), episodes and truncations renumbered to
  // batch columns, frees their slots and returns true; otherwise returns false and leaves `out`
  // alone. `origin`, when given, says where each column came from.
  bool take(rollout::RolloutBuffer& out, BatchOrigin* origin = nullptr);
  // A batch short of environments that were lost: when at least min_envs (> 0) are buffered, takes
  // them all (at most num_envs) as take() does, and sets `out` to that many environments.
  bool takeShort(rollout::RolloutBuffer& out, int min_envs, BatchOrigin* origin = nullptr);

  const CollectorStats& stats() const { return stats_; }
  const CollectorConfig& config() const { return cfg_; }

 private:
  void takeEnvs(rollout::RolloutBuffer& out, int num_envs, BatchOrigin* origin);
  int freeSlotFor(int64_t version);  // -1 when full of environments at least as new
  void release(int slot);
  // Forgets the truncations and episodes of released slots (before a slot is reused or read).
  void dropEventsOfFreeSlots();

  CollectorConfig cfg_;
  int capacity_ = 0;
  int64_t version_ = 0;
  int used_ = 0;
  uint64_t arrivals_ = 0;
  CollectorStats stats_;

  // Slot s is environment s of the pool. Its truncations have final_index t * capacity + s and
  // its episodes episode_env s, in arrival order (not sorted: take() orders them).
  rollout::Rollout pool_;
  bool events_stale_ = false;  // some released slot may still have events in pool_
  std::vector<char> in_use_;
  std::vector<int64_t> slot_version_;
  std::vector<uint64_t> slot_arrival_;
  std::vector<int32_t> slot_actor_, slot_env_;
  std::vector<int> free_, order_, batch_column_;
  std::vector<int> chunk_slots_;                          // slot of each environment of the chunk being added
  std::vector<std::pair<int32_t, int32_t>> batch_finals_;  // scratch of sortFinals: (batch step index, entry)
  std::vector<float> sorted_final_obs_;                   // scratch of sortFinals
};

}  // namespace masa::learner
