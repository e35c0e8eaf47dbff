// The learner's gate for rollout chunks: every chunk is hostile until validated.
//
// A chunk is accepted only if it belongs to this run, has the learner's dimensions, consistent
// array lengths, indices in range, finite floats, a policy version within the allowed lag, and
// was not seen before. Everything else is dropped and counted under its reason (DropStats), with
// a rate-limited warning on stderr. An accepted chunk is usable on its own: chunks hold whole
// environments, so a rollout whose other chunks were lost still delivers the environments that
// arrived, and nothing ever waits for a missing chunk.
//
// Per actor it follows one incarnation (the actor process) and its rollout numbering (rollout_seq,
// from 0): duplicates are detected within the last dedup_window rollouts, and chunks that never
// arrived are counted as kLost once the actor is loss_horizon rollouts past their rollout (a wholly
// lost rollout counts as many chunks as the actor's last rollout had). Only an accepted chunk moves
// this bookkeeping; a chunk dropped as out of date only marks its rollout's chunk as arrived (so
// that it is not also counted lost), and only within the window. Rollouts behind the window are
// duplicates. An accepted chunk of another incarnation, or more than dedup_window ahead of the
// numbering, is used, but believed only when its actor's next rollout follows it before the
// current numbering moves on: then it is a restarted actor (another incarnation: a new numbering)
// or an outage (the gap is lost). Restarts rest on the incarnation alone, never on the numbering.
// A replayed chunk, or a copy of a live one with a wild number, therefore neither counts chunks
// lost nor reports a restart.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <vector>

#include "learner/intake/drop_reason.hpp"
#include "common/transport/wire_guard.hpp"
#include "masa/lcmt_rollout_chunk.hpp"

namespace masa::learner {

struct AssemblerConfig {
  int64_t run_id = 0;
  int horizon = 0;  // the learner's T, obs_dim and act_dim; chunks must match exactly
  int obs_dim = 0;
  int act_dim = 0;
  int max_policy_lag = 0;            // accept versions in [current - lag, current]
  int max_actors = 4096;             // actor_id must be below
  int max_envs_per_actor = 1 << 16;  // env_offset + num_envs must not exceed
  int max_terms = 256;               // num_terms must not exceed
  int dedup_window = 16;             // rollouts per actor remembered to detect duplicates
  int loss_horizon = 2;              // rollouts an actor must be past a rollout before its gaps count as lost
  double warn_interval_s = 5.0;      // at most one warning per reason per interval; < 0: silent
};

// A chunk that passed validation. Only RolloutAssembler makes them, so code that takes one (the
// BatchCollector) cannot be handed unchecked input. Refers to the message it was made from.
class ValidatedChunk {
 public:
  const masa::lcmt_rollout_chunk& msg() const { return *msg_; }
  int64_t version() const { return msg_->policy_version; }
  int numEnvs() const { return msg_->num_envs; }

 private:
  friend class RolloutAssembler;
  explicit ValidatedChunk(const masa::lcmt_rollout_chunk* m) : msg_(m) {}
  const masa::lcmt_rollout_chunk* msg_;
};

struct Verdict {
  DropReason reason = DropReason::kMalformed;
  std::optional<ValidatedChunk> chunk;  // set exactly when reason == kAccepted
  explicit operator bool() const { return chunk.has_value(); }
};

// What arrived from one actor id, over all its processes.
struct ActorTally {
  int64_t accepted = 0;    // chunks accepted
  int64_t lost = 0;        // chunks that never arrived (a chunk arriving after it was counted is taken off)
  int64_t numberings = 0;  // rollout numberings seen: 1 + restarts
};

class RolloutAssembler {
 public:
  explicit RolloutAssembler(const AssemblerConfig& config);

  // The learner's current parameter version; chunks newer than it, or older than
  // version - max_policy_lag, are dropped from now on.
  void setLearnerVersion(int64_t version) { version_ = version; }
  int64_t learnerVersion() const { return version_; }

  // Validates a decoded chunk; an accepted chunk refers to `msg`, which must outlive its use.
  Verdict accept(const masa::lcmt_rollout_chunk& msg);
  // Bounds-checks and decodes raw LCM bytes into an internal message (reused, so the returned
  // chunk is valid until the next acceptEncoded), then validates it.
  Verdict acceptEncoded(const void* data, int size);

  const DropStats& stats() const { return stats_; }
  // Why the wire guard rejected the bytes acceptEncoded counted as kMalformed.
  const transport::WireRejects& wireRejects() const { return wire_rejects_; }
  const AssemblerConfig& config() const { return cfg_; }
  // All zero for an actor id never seen.
  const ActorTally& actorTally(int actor_id) const;

 private:
  struct SeenRollout {
    int64_t seq = -1;  // -1: slot unused
    int32_t num_chunks = 0;
    std::vector<uint64_t> bits;     // one bit per chunk index: accepted (duplicates are checked here)
    std::vector<uint64_t> arrived;  // chunks that came but were out of date: not lost, not accepted
  };
  struct ActorWindow {
    std::vector<SeenRollout> rollouts;  // 2 * dedup_window slots, replaced oldest first
    int64_t first = -1;                 // first rollout seen in the current numbering (-1: none yet)
    int64_t newest = -1;                // newest rollout seen in it
    int64_t closed = -1;                // rollouts up to this one have had their losses counted
    int32_t num_chunks = 0;             // chunks per rollout, as last seen
    int64_t incarnation = 0;            // of the current numbering
    SeenRollout candidate;              // an accepted rollout far from the numbering, not yet believed
    int64_t candidate_incarnation = 0;  // ... and its incarnation
    ActorTally tally;
  };

  DropReason validate(const masa::lcmt_rollout_chunk& m) const;
  // Records a validated chunk for duplicate detection and loss counting, and moves the actor's
  // numbering. Returns kAccepted, kDuplicate or kOutOfRange.
  DropReason markAccepted(const masa::lcmt_rollout_chunk& m);
  // Notes that a well-formed but out-of-date chunk arrived, so that it is not counted lost; moves
  // nothing else, and nothing at all outside the actor's window.
  void markArrived(const masa::lcmt_rollout_chunk& m);
  // An accepted chunk far from the numbering, or of another incarnation: held as a candidate until
  // its next rollout confirms it.
  DropReason acceptFarChunk(ActorWindow& a, const masa::lcmt_rollout_chunk& m);
  ActorWindow& windowOf(int actor_id);
  SeenRollout* findSlot(ActorWindow& a, int64_t seq);
  SeenRollout& claimSlot(ActorWindow& a, int64_t seq, int32_t num_chunks);  // replaces the oldest
  // Counts the missing chunks of rollouts (closed, upto] of the current numbering.
  void closeRollouts(ActorWindow& a, int actor_id, int64_t upto);
  void startNumbering(ActorWindow& a, int actor_id, int64_t incarnation, int64_t seq);
  Verdict finish(DropReason reason, const masa::lcmt_rollout_chunk* m);
  bool warnDue(DropReason reason);

  AssemblerConfig cfg_;
  int64_t version_ = 0;
  DropStats stats_;
  transport::WireRejects wire_rejects_{};
  std::vector<ActorWindow> actors_;  // indexed by actor_id, grown on first sight
  masa::lcmt_rollout_chunk decoded_;  // reused by acceptEncoded

  // Rate limiting of warnings, per reason.
  std::chrono::steady_clock::time_point last_warn_[kNumDropReasons];
  int64_t suppressed_[kNumDropReasons] = {};
  bool warned_[kNumDropReasons] = {};
};

}  // namespace masa::learner
