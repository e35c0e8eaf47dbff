// Whether a robot state message is news: its utime must advance past the last state taken, and
// must not claim that more robot time has passed than passed here (the receive clock) by more than
// a lead. Without the second rule one state with a far-future utime, from anyone on the robot's
// LAN, made every later real state look like a repeat, and the watchdog stopped the robot
// (docs/inputs.md, gap 2).
//
// A stream the robot really sends can also move backwards (its SDK restarted, its clock reset) or
// jump (a clock step), and then every state would be refused forever. So states that are refused
// but consistent among themselves (each utime advancing no faster than the receive clock, plus the
// lead) are counted, and after `resync_after` of them in a row the newest becomes the new baseline.
// One datagram cannot do that; a sender that keeps injecting consistent states can, but such a
// sender can drive the policy anyway on an unsigned channel (masa_deploy verifies the robot's
// signature unless --insecure).
//
// The lead is measured from the baseline's offset (utime - receive time), which only a resync
// moves: a state taken inside the lead does not raise it (issue #55, item 2). Before, every state
// taken raised it to its own offset, so forged states interleaved with the real ones, each one
// lead ahead of the last, walked it forward without end and every real state became a repeat. A
// robot clock that drifts ahead of ours leaves the lead after a while and is resynced like a step.
#pragma once

#include <cstdint>

namespace masa::deploy {

class StateFreshness {
 public:
  enum class Verdict {
    kNew,      // newer than the last state taken, and not ahead of the receive clock
    kRepeat,   // not newer than the last state taken
    kAhead,    // claims more time passed than the receive clock allows
    kResynced  // refused until now, but the last `resync_after` in a row were consistent: taken
  };

  // max_lead_us: how much further a state's utime may advance than its receive time did (network
  // jitter and clock drift); resync_after >= 2.
  explicit StateFreshness(int64_t max_lead_us = 25000, int resync_after = 3);

  // Judges a state stamped `utime` (robot clock) received at `rx_us` (local steady clock), and
  // takes it as the newest when the verdict is kNew or kResynced.
  Verdict judge(int64_t utime, int64_t rx_us);

  int64_t resyncs() const { return resyncs_; }
  int64_t refusedAhead() const { return refused_ahead_; }

 private:
  void takeAsBaseline(int64_t utime, int64_t rx_us);

  int64_t max_lead_us_;
  int resync_after_;
  bool have_ = false;
  int64_t last_utime_ = 0;
  __int128 base_offset_ = 0;  // utime - rx of the baseline: the lead counts from here
  // The current run of refused states: its newest, and how many in a row were consistent.
  int64_t run_utime_ = 0, run_rx_us_ = 0;
  int run_length_ = 0;
  int64_t resyncs_ = 0, refused_ahead_ = 0;
};

}  // namespace masa::deploy
