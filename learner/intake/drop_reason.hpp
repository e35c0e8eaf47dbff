// Why the learner drops a rollout chunk, and the counters it keeps per reason (reported in
// lcmt_learner_stats). Every drop is counted: loss is expected on UDP, silent loss is not.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace masa::learner {

enum class DropReason : int {
  kAccepted = 0,   // not a drop
  kMalformed,      // bytes that do not decode as lcmt_rollout_chunk (bad hash, truncated, lengths past the end)
  kWrongRun,       // run_id of another training run
  kWrongDims,      // horizon / obs_dim / act_dim differ from the learner's
  kBadLength,      // an array length field disagrees with the dimensions, or an array with its length field
  kNonFinite,      // NaN or Inf in a float
  kFutureVersion,  // policy_version newer than the learner's current version
  kTooOld,         // policy_version older than current - max_policy_lag
  kDuplicate,      // the same (actor, rollout, chunk) already arrived, or its rollout is too far behind to tell
  kOutOfRange,     // an index or enumerated value out of its range (chunk index, env range, final index, flags)
  kWrongTerms,     // reward term names other than the task's (they name metrics.csv's columns and the curve's plots)
  // Never a verdict of the assembler: no valid tag of the run key, dropped by the Transport before
  // the assembler sees the bytes (so it moves no actor's state); the learner adds its count.
  kUnauthenticated,
  // Never verdicts of the assembler either: a signed run's refusals (common/transport/message_sign.hpp),
  // by the Transport before the assembler sees the bytes.
  kUnknownSender,        // signed by a sender the roster does not list
  kNotPermitted,         // by a sender the roster does not let publish rollouts
  kClaimsAnotherActor,   // signed by one actor, naming another actor id
  kReplayed,             // a counter this actor used before on this channel
  kBeyondWindow,         // a counter too far below this actor's newest
  kBeforeStart,          // signed before this learner started: a recording replayed after a restart
  kAnotherRanksActor,    // an actor that reports to another learner rank of the MPI job
  // Never a verdict: chunks that never arrived (UDP loss, a full receive buffer, an actor killed
  // while sending), counted by the assembler from the gaps in each actor's rollout numbering.
  kLost,
  kCount
};

inline constexpr int kNumDropReasons = static_cast<int>(DropReason::kCount);

// Stable snake_case names, as sent in lcmt_learner_stats.drop_reason_names.
std::string_view dropReasonName(DropReason r);

struct DropStats {
  std::array<int64_t, kNumDropReasons> count{};  // count[kAccepted] = accepted chunks
  int64_t operator[](DropReason r) const { return count[static_cast<int>(r)]; }
  int64_t dropped() const;  // all reasons but kAccepted
};

}  // namespace masa::learner
