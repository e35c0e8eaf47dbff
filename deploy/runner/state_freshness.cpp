#include "deploy/runner/state_freshness.hpp"

#include <algorithm>
#include <stdexcept>

namespace masa::deploy {

StateFreshness::StateFreshness(int64_t max_lead_us, int resync_after)
    : max_lead_us_(max_lead_us), resync_after_(resync_after) {
  if (max_lead_us < 0 || resync_after < 2) throw std::invalid_argument("StateFreshness: max_lead_us >= 0, resync_after >= 2");
}

void StateFreshness::takeAsBaseline(int64_t utime, int64_t rx_us) {
  have_ = true;
  last_utime_ = utime;
  base_offset_ = static_cast<__int128>(utime) - rx_us;
  run_length_ = 0;
}

StateFreshness::Verdict StateFreshness::judge(int64_t utime, int64_t rx_us) {
  if (!have_) {
    takeAsBaseline(utime, rx_us);
    return Verdict::kNew;
  }
  // 128 bits: a hostile utime may be anything, and differences of int64 values overflow.
  const __int128 offset = static_cast<__int128>(utime) - rx_us;
  const bool newer = utime > last_utime_;
  const bool within_lead = offset <= base_offset_ + max_lead_us_;
  if (newer && within_lead) {
    last_utime_ = utime;  // the baseline's offset stays: taken states do not move the lead
    run_length_ = 0;
    return Verdict::kNew;
  }
  const bool continues_run = run_length_ > 0 && utime > run_utime_ &&
                             static_cast<__int128>(utime) - run_utime_ <=
                                 static_cast<__int128>(rx_us) - run_rx_us_ + max_lead_us_;
  run_length_ = continues_run ? run_length_ + 1 : 1;
  run_utime_ = utime;
  run_rx_us_ = rx_us;
  if (run_length_ >= resync_after_) {
    takeAsBaseline(utime, rx_us);
    ++resyncs_;
    return Verdict::kResynced;
  }
  if (!newer) return Verdict::kRepeat;
  ++refused_ahead_;
  return Verdict::kAhead;
}

}  // namespace masa::deploy
