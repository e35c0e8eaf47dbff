// The learner's gate for rollout chunks: every chunk is hostile until validated.
//
// A chunk is accepted only if it belongs to this run, has the learner's dimensions, consistent
// array lengths, indices in range, finite floats, a policy version within the allowed lag, and
// was not seen before. Everything else is dropped and counted under its reason (DropStats), with
// a rate-limited warning on stderr. An accepted chunk is usable on its own: chunks hold whole
// environments, so a rollout whose other chunks were lost still delivers the environments that
// arrived, and nothing ever waits for a missing chunk.
//
// Per actor it follows one incarnation and its rollout numbering (ActorNumbering,
// actor_numbering.hpp): duplicates within the last dedup_window rollouts, chunks that never
// arrived counted as kLost, restarts believed only when confirmed. Only an accepted chunk moves that
// bookkeeping; a chunk dropped as out of date only marks its chunk as arrived.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "learner/intake/actor_numbering.hpp"
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
  // The task's reward term names: a chunk must carry exactly these (empty: any, for tests of other
  // things). The learner writes them into metrics.csv's header and the curve's gnuplot script, so
  // they are never taken from the network.
  std::vector<std::string> term_names;
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
  DropReason validate(const masa::lcmt_rollout_chunk& m) const;
  ActorNumbering& numberingOf(int actor_id);
  // Counts and reports what a chunk changed in its actor's numbering.
  void apply(int actor_id, const masa::lcmt_rollout_chunk& m, const ActorNumbering::Change& change);
  Verdict finish(DropReason reason, const masa::lcmt_rollout_chunk* m);
  bool warnDue(DropReason reason);

  AssemblerConfig cfg_;
  int64_t version_ = 0;
  DropStats stats_;
  transport::WireRejects wire_rejects_{};
  std::vector<ActorNumbering> actors_;  // indexed by actor_id, grown on first sight
  masa::lcmt_rollout_chunk decoded_;  // reused by acceptEncoded

  // Rate limiting of warnings, per reason.
  std::chrono::steady_clock::time_point last_warn_[kNumDropReasons];
  int64_t suppressed_[kNumDropReasons] = {};
  bool warned_[kNumDropReasons] = {};
};

}  // namespace masa::learner
