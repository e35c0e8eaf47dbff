// Splits one actor rollout into lcmt_rollout_chunk messages of whole environments, each under a
// byte budget, so that every chunk is one LCM datagram (LCM fragments above 64 KB, and losing one
// fragment loses the message) and a lost chunk loses only its own environments.
//
// Packing is greedy over consecutive environments, which is optimal for an ordered split: no
// split of 0..E-1 into contiguous runs under the budget has fewer chunks. The messages are kept
// and refilled each rollout; their arrays are reserved for the largest chunk on creation, so
// steady state does not allocate.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/rollout/rollout.hpp"
#include "masa/lcmt_rollout_chunk.hpp"

namespace masa::actor {

// Encoded bytes per chunk. Below LCM's 64 KB fragmentation threshold with room for the channel
// name and LCM's own header.
inline constexpr int kDefaultChunkBytes = 60000;

// Who produced a rollout and with which parameters; copied into every chunk.
struct RolloutIdentity {
  int64_t run_id = 0;
  int32_t actor_id = 0;
  int64_t rollout_seq = 0;
  int64_t policy_version = 0;
  int64_t incarnation = 0;  // the actor process (lcmt_rollout_chunk.incarnation)
};

class RolloutChunker {
 public:
  explicit RolloutChunker(int byte_budget = kDefaultChunkBytes);

  // Fills the chunks of `rollout` and returns them; the span stays valid until the next split().
  // An environment that alone exceeds the budget (only possible with many truncations or
  // episodes) still goes out, alone in its chunk, and is counted in oversizeChunks().
  std::span<const masa::lcmt_rollout_chunk> split(const rollout::Rollout& rollout, const RolloutIdentity& id);

  int byteBudget() const { return budget_; }
  long oversizeChunks() const { return oversize_; }

  // Encoded size of a chunk of this rollout's shape holding no environment.
  static int emptyChunkBytes(int act_dim, const std::vector<std::string>& term_names);
  // Encoded bytes one environment adds, without its truncations and episodes.
  static int envBytes(int horizon, int obs_dim, int act_dim);
  // Encoded bytes one truncation / one finished episode adds.
  static int finalBytes(int obs_dim);
  static int episodeBytes(int num_terms);
  // Most environments one chunk can hold when they have no truncations or episodes (>= 1).
  static int maxEnvsPerChunk(int byte_budget, int horizon, int obs_dim, int act_dim,
                             const std::vector<std::string>& term_names = {});

 private:
  void plan(const rollout::Rollout& r);
  void fill(masa::lcmt_rollout_chunk& c, const rollout::Rollout& r, const RolloutIdentity& id, int index,
            int num_chunks, int offset, int n);

  int budget_;
  long oversize_ = 0;
  std::vector<masa::lcmt_rollout_chunk> chunks_;
  std::vector<int> env_finals_, env_episodes_;  // per environment, this rollout
  std::vector<int> chunk_offset_, chunk_envs_;  // the plan
  std::vector<int> env_map_;                    // rollout environment -> chunk environment (or -1), for fill
};

}  // namespace masa::actor
