#include "learner/intake/actor_numbering.hpp"

#include <algorithm>
#include <bit>
#include <utility>

namespace masa::learner {

namespace {

void resetSlot(auto& slot, int64_t seq, int32_t num_chunks) {
  slot.seq = seq;
  slot.num_chunks = num_chunks;
  slot.bits.assign((num_chunks + 63) / 64, 0);
  slot.arrived.assign(slot.bits.size(), 0);
}

bool anyBit(const std::vector<uint64_t>& bits) {
  for (uint64_t b : bits)
    if (b != 0) return true;
  return false;
}

}  // namespace

ActorNumbering::ActorNumbering(int dedup_window, int loss_horizon)
    : dedup_window_(dedup_window), loss_horizon_(loss_horizon) {
  // Twice the window: rollouts up to dedup_window behind the newest, and out-of-date arrivals up
  // to dedup_window ahead of it.
  rollouts_.resize(2 * static_cast<std::size_t>(dedup_window));
}

ActorNumbering::SeenRollout* ActorNumbering::findSlot(int64_t seq) {
  for (SeenRollout& r : rollouts_)
    if (r.seq == seq) return &r;
  return nullptr;
}

ActorNumbering::SeenRollout& ActorNumbering::claimSlot(int64_t seq, int32_t num_chunks) {
  // The slots hold at most dedup_window rollouts behind the newest and dedup_window ahead of it, so
  // the oldest slot is unused or outside the window (its losses already counted).
  SeenRollout* oldest = &rollouts_[0];
  for (SeenRollout& r : rollouts_)
    if (r.seq < oldest->seq) oldest = &r;
  resetSlot(*oldest, seq, num_chunks);
  return *oldest;
}

void ActorNumbering::closeRollouts(int64_t upto, Change& change) {
  int64_t lost = 0;
  for (int64_t x = std::max(closed_ + 1, first_); x <= upto; ++x) {
    const SeenRollout* seen = nullptr;
    for (const SeenRollout& r : rollouts_)
      if (r.seq == x) seen = &r;
    if (seen == nullptr) {
      lost += num_chunks_;  // wholly lost: as many chunks as the actor's last rollout had
      continue;
    }
    int arrived = 0;
    for (std::size_t i = 0; i < seen->bits.size(); ++i) arrived += std::popcount(seen->bits[i] | seen->arrived[i]);
    lost += seen->num_chunks - arrived;
  }
  closed_ = std::max(closed_, upto);
  tally_.lost += lost;
  change.lost += lost;
}

void ActorNumbering::startNumbering(int64_t incarnation, int64_t seq, Change& change) {
  const bool restart = first_ >= 0;
  if (restart) {
    closeRollouts(newest_, change);  // the old numbering's last rollouts are final now
    change.numbering = Change::Numbering::kRestarted;
    change.previous_incarnation = incarnation_;
  } else {
    change.numbering = Change::Numbering::kJoined;
  }
  for (SeenRollout& r : rollouts_) r.seq = -1;
  incarnation_ = incarnation;
  first_ = newest_ = seq;
  closed_ = seq - 1;
  ++tally_.numberings;
}

void ActorNumbering::uncountLost(Change& change) {
  // Arrived after its rollout's losses were counted: it was not lost after all.
  if (tally_.lost <= 0) return;
  --tally_.lost;
  ++change.found;
}

DropReason ActorNumbering::accept(const ChunkPlace& c, Change& change) {
  const int64_t s = c.rollout_seq, w = dedup_window_;
  if (first_ < 0) startNumbering(c.incarnation, s, change);  // first sight
  if (c.incarnation != incarnation_) return acceptFar(c, change);

  SeenRollout* slot = findSlot(s);
  if (slot == nullptr) {
    if (s > newest_ + w) return acceptFar(c, change);
    if (s <= newest_ - w) return DropReason::kDuplicate;  // behind the window: a replay or a straggler we can no longer check
    if (s > newest_) {
      candidate_.seq = -1;  // the numbering moved on: a far rollout seen before it was not a restart
      closeRollouts(s - loss_horizon_, change);
      newest_ = s;
    }
    slot = &claimSlot(s, c.num_chunks);
  } else if (slot->num_chunks != c.num_chunks) {
    // Chunks of one rollout disagree on how many there are. Only arrivals of out-of-date chunks
    // (perhaps hostile) made the slot so far: the first accepted chunk decides.
    if (anyBit(slot->bits)) return DropReason::kOutOfRange;
    resetSlot(*slot, s, c.num_chunks);
  }
  const std::size_t w64 = c.chunk_index / 64;
  const uint64_t bit = uint64_t{1} << (c.chunk_index % 64);
  if (slot->bits[w64] & bit) return DropReason::kDuplicate;
  const bool first_arrival = !(slot->arrived[w64] & bit);
  slot->bits[w64] |= bit;
  num_chunks_ = c.num_chunks;
  ++tally_.accepted;
  if (first_arrival && s <= closed_) uncountLost(change);
  return DropReason::kAccepted;
}

DropReason ActorNumbering::acceptFar(const ChunkPlace& c, Change& change) {
  SeenRollout& cand = candidate_;
  const int64_t s = c.rollout_seq, w = dedup_window_;
  const bool same_candidate = cand.seq >= 0 && candidate_incarnation_ == c.incarnation;
  if (same_candidate && s > cand.seq && s <= cand.seq + w) {
    // The far rollout's successor, with no progress of the current numbering in between: a
    // restarted actor (another incarnation), or an outage that lost the rollouts in the gap.
    SeenRollout far = std::move(cand);
    cand.seq = -1;
    if (c.incarnation != incarnation_) {
      startNumbering(c.incarnation, far.seq, change);
    } else {
      closeRollouts(far.seq - loss_horizon_, change);
      newest_ = far.seq;
    }
    num_chunks_ = far.num_chunks;
    claimSlot(far.seq, far.num_chunks) = std::move(far);
    return accept(c, change);  // within the window now
  }
  if (!same_candidate || cand.seq != s || cand.num_chunks != c.num_chunks) {  // replaces an unconfirmed one
    resetSlot(cand, s, c.num_chunks);
    candidate_incarnation_ = c.incarnation;
  }
  const std::size_t w64 = c.chunk_index / 64;
  const uint64_t bit = uint64_t{1} << (c.chunk_index % 64);
  if (cand.bits[w64] & bit) return DropReason::kDuplicate;
  cand.bits[w64] |= bit;
  ++tally_.accepted;
  return DropReason::kAccepted;
}

void ActorNumbering::arrived(const ChunkPlace& c, Change& change) {
  const int64_t s = c.rollout_seq, w = dedup_window_;
  if (first_ < 0 || c.incarnation != incarnation_ || s <= newest_ - w || s > newest_ + w) return;
  SeenRollout* slot = findSlot(s);
  if (slot == nullptr) {
    slot = &claimSlot(s, c.num_chunks);
  } else if (slot->num_chunks != c.num_chunks) {
    return;
  }
  const std::size_t w64 = c.chunk_index / 64;
  const uint64_t bit = uint64_t{1} << (c.chunk_index % 64);
  if ((slot->bits[w64] | slot->arrived[w64]) & bit) return;
  slot->arrived[w64] |= bit;
  if (s <= closed_) uncountLost(change);
}

}  // namespace masa::learner
