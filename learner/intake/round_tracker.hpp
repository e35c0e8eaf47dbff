// When may a batch form short of environments? When the chunks it lacks are known to be lost, not
// still on their way: otherwise a lost chunk stalls the learner until the actors' next rollouts
// (an actor waits for parameters that cannot come, then simulates a whole rollout to replace a
// few environments; at 5% datagram loss that was 0.79 of the lossless update rate).
//
// A round is the time between two updates. The actors expected in a round are those that delivered
// in this round or the one before (an actor silent for a whole round is dead or behind, and the
// batch does not wait for it). The round has settled when every expected actor has delivered in
// it, and the latest rollout of each is complete, or its last chunk came (chunks of one rollout
// are published back to back, in order, so the chunks missing before it are lost), or nothing of
// it came for grace_s (the last chunk itself was lost).
//
// Only accepted chunks are reported here: a forged or stale chunk moves nothing. Pure bookkeeping
// over the times it is given: tested without a clock.
#pragma once

#include <chrono>
#include <cstdint>
#include <vector>

namespace masa::learner {

class RoundTracker {
 public:
  using Clock = std::chrono::steady_clock;

  explicit RoundTracker(double grace_s) : grace_(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(grace_s))) {}

  // An accepted chunk of an actor's rollout.
  void chunkArrived(int actor_id, int64_t rollout_seq, int chunk_index, int num_chunks, Clock::time_point now);
  // The learner updated: a new round begins.
  void newRound();

  // See above. False in the first round (nobody is known to be expected yet).
  bool settled(Clock::time_point now) const;
  // When settled() may next turn true by time alone (the earliest grace end of an incomplete
  // rollout); Clock::time_point::max() when only an arrival can settle the round.
  Clock::time_point nextDeadline() const;

 private:
  struct ActorRound {
    int64_t rollout_seq = 0;
    int num_chunks = 0;
    int arrived = 0;             // distinct chunks of that rollout arrived (accepted chunks are never duplicates)
    bool last_arrived = false;   // its chunk num_chunks - 1 came
    Clock::time_point latest{};  // the last arrival
    bool delivered_now = false;  // delivered in this round
    bool delivered_before = false;  // delivered in the previous round
    bool complete() const { return arrived >= num_chunks || last_arrived; }
  };

  Clock::duration grace_;
  std::vector<ActorRound> actors_;  // indexed by actor id (validated below the assembler's max_actors)
  bool any_round_before_ = false;
};

}  // namespace masa::learner
