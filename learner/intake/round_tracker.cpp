#include "learner/intake/round_tracker.hpp"

#include <algorithm>

#include "common/core/check.hpp"

namespace masa::learner {

void RoundTracker::chunkArrived(int actor_id, int64_t rollout_seq, int chunk_index, int num_chunks,
                                Clock::time_point now) {
  MASA_CHECK(actor_id >= 0 && num_chunks > 0 && chunk_index >= 0 && chunk_index < num_chunks,
             "round tracker: chunk " << chunk_index << " of " << num_chunks << " from actor " << actor_id);
  if (actor_id >= static_cast<int>(actors_.size())) actors_.resize(actor_id + 1);
  ActorRound& a = actors_[actor_id];
  if (!a.delivered_now || a.rollout_seq != rollout_seq) {  // the actor's first chunk of a rollout this round
    a.rollout_seq = rollout_seq;
    a.num_chunks = num_chunks;
    a.arrived = 0;
    a.last_arrived = false;
  }
  a.delivered_now = true;
  ++a.arrived;
  a.last_arrived = a.last_arrived || chunk_index == num_chunks - 1;
  a.latest = now;
}

void RoundTracker::newRound() {
  for (ActorRound& a : actors_) {
    a.delivered_before = a.delivered_now;
    a.delivered_now = false;
  }
  any_round_before_ = true;
}

bool RoundTracker::settled(Clock::time_point now) const {
  if (!any_round_before_) return false;
  bool anyone = false;
  for (const ActorRound& a : actors_) {
    if (!a.delivered_now && !a.delivered_before) continue;  // not expected
    if (!a.delivered_now) return false;                     // expected, nothing yet
    anyone = true;
    if (!a.complete() && now - a.latest < grace_) return false;
  }
  return anyone;
}

RoundTracker::Clock::time_point RoundTracker::nextDeadline() const {
  Clock::time_point next = Clock::time_point::max();
  for (const ActorRound& a : actors_) {
    if (a.delivered_now && !a.complete()) next = std::min(next, a.latest + grace_);
  }
  return next;
}

}  // namespace masa::learner
