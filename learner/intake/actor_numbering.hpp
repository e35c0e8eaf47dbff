// One actor id's rollout numbering as the learner follows it (RolloutAssembler keeps one per actor):
// the incarnation (the actor process) and its rollouts (rollout_seq, from 0) seen in a window of
// 2 x dedup_window slots; duplicates within the window; chunks that never arrived counted lost once
// the actor is loss_horizon rollouts past their rollout (a wholly lost rollout counts as many chunks
// as the actor's last rollout had), and taken off again if they arrive after all. An accepted chunk
// of another incarnation, or more than dedup_window ahead, is a candidate, believed only when the
// actor's next rollout follows it before the current numbering moves on: a restarted actor (a new
// numbering) or an outage (the gap is lost). So a replayed chunk, or a copy with a wild number,
// neither counts chunks lost nor reports a restart. What changed is returned as an
// ActorNumbering::Change for the assembler to count and report.
#pragma once

#include <cstdint>
#include <vector>

#include "learner/intake/drop_reason.hpp"

namespace masa::learner {

// What arrived from one actor id, over all its processes.
struct ActorTally {
  int64_t accepted = 0;    // chunks accepted
  int64_t lost = 0;        // chunks that never arrived (a chunk arriving after it was counted is taken off)
  int64_t numberings = 0;  // rollout numberings seen: 1 + restarts
};

// One chunk's place in its actor's numbering (the fields of a chunk that passed validation).
struct ChunkPlace {
  int64_t incarnation = 0;
  int64_t rollout_seq = 0;
  int32_t num_chunks = 0;
  int32_t chunk_index = 0;
};

class ActorNumbering {
 public:
  // What a chunk changed, for the assembler's counts and messages.
  struct Change {
    int64_t lost = 0;   // chunks newly counted lost
    int64_t found = 0;  // chunks counted lost before that arrived after all
    enum class Numbering { kSame, kJoined, kRestarted } numbering = Numbering::kSame;
    int64_t previous_incarnation = 0;  // kRestarted: the incarnation before
  };

  ActorNumbering(int dedup_window, int loss_horizon);

  // A chunk that passed validation: kAccepted, kDuplicate or kOutOfRange (chunks of one rollout
  // disagreeing on their count).
  DropReason accept(const ChunkPlace& c, Change& change);
  // A well-formed chunk dropped as out of date: it arrived, so it is not counted lost. Moves
  // nothing else, and nothing at all outside the window of the current numbering.
  void arrived(const ChunkPlace& c, Change& change);

  const ActorTally& tally() const { return tally_; }
  int64_t incarnation() const { return incarnation_; }
  int64_t firstRollout() const { return first_; }  // of the current numbering

 private:
  struct SeenRollout {
    int64_t seq = -1;  // -1: slot unused
    int32_t num_chunks = 0;
    std::vector<uint64_t> bits;     // one bit per chunk index: accepted (duplicates are checked here)
    std::vector<uint64_t> arrived;  // chunks that came but were out of date: not lost, not accepted
  };

  DropReason acceptFar(const ChunkPlace& c, Change& change);
  SeenRollout* findSlot(int64_t seq);
  SeenRollout& claimSlot(int64_t seq, int32_t num_chunks);  // replaces the oldest
  void closeRollouts(int64_t upto, Change& change);          // counts the losses of (closed, upto]
  void startNumbering(int64_t incarnation, int64_t seq, Change& change);
  void uncountLost(Change& change);

  int dedup_window_, loss_horizon_;
  std::vector<SeenRollout> rollouts_;  // 2 x dedup_window slots, replaced oldest first
  int64_t first_ = -1;                 // first rollout seen in the current numbering (-1: none yet)
  int64_t newest_ = -1;                // newest rollout seen in it
  int64_t closed_ = -1;                // rollouts up to this one have had their losses counted
  int32_t num_chunks_ = 0;             // chunks per rollout, as last seen
  int64_t incarnation_ = 0;            // of the current numbering
  SeenRollout candidate_;              // an accepted rollout far from the numbering, not yet believed
  int64_t candidate_incarnation_ = 0;  // ... and its incarnation
  ActorTally tally_;
};

}  // namespace masa::learner
