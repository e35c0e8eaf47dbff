#include "learner/intake/drop_reason.hpp"

namespace masa::learner {

std::string_view dropReasonName(DropReason r) {
  switch (r) {
    case DropReason::kAccepted: return "accepted";
    case DropReason::kMalformed: return "malformed";
    case DropReason::kWrongRun: return "wrong_run";
    case DropReason::kWrongDims: return "wrong_dims";
    case DropReason::kBadLength: return "bad_length";
    case DropReason::kNonFinite: return "non_finite";
    case DropReason::kFutureVersion: return "future_version";
    case DropReason::kTooOld: return "too_old";
    case DropReason::kDuplicate: return "duplicate";
    case DropReason::kOutOfRange: return "out_of_range";
    case DropReason::kWrongTerms: return "wrong_terms";
    case DropReason::kUnauthenticated: return "unauthenticated";
    case DropReason::kUnknownSender: return "unknown_sender";
    case DropReason::kNotPermitted: return "not_permitted";
    case DropReason::kClaimsAnotherActor: return "claims_another_actor";
    case DropReason::kReplayed: return "replayed";
    case DropReason::kBeyondWindow: return "beyond_window";
    case DropReason::kBeforeStart: return "before_start";
    case DropReason::kAnotherRanksActor: return "another_ranks_actor";
    case DropReason::kLost: return "lost";
    case DropReason::kCount: break;
  }
  return "unknown";
}

int64_t DropStats::dropped() const {
  int64_t n = 0;
  for (int i = 1; i < kNumDropReasons; ++i) n += count[i];
  return n;
}

}  // namespace masa::learner
