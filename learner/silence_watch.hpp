// Says when no rollout data has arrived for a while, and which actors the learner last heard from:
// a run whose actors all died (or never reached the learner: another --url, another run id)
// otherwise just stalls without a word. Only accepted chunks count as hearing from an actor (a
// rejected message proves nothing about who sent it). Time is passed in, so it tests without sleeping.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>

namespace masa::learner {

class SilenceWatch {
 public:
  using Clock = std::chrono::steady_clock;

  // warn_after_s <= 0: never warns.
  SilenceWatch(double warn_after_s, Clock::time_point start);

  // An accepted chunk from actor `actor_id`.
  void heard(int actor_id, Clock::time_point now);

  // A warning when nothing was heard for warn_after_s (then again every warn_after_s while the
  // silence lasts), else nothing. `update` and `dropped_chunks` (the assembler's running total) go
  // into the text: chunks dropped during the silence point at a mismatched sender.
  std::optional<std::string> check(Clock::time_point now, int64_t update, int64_t dropped_chunks);

  // The learner was busy for `d` (an update, its evaluation, its checkpoint) and read no message
  // meanwhile: that time is not the actors' silence. An off-policy round's gradient steps take
  // tens of seconds, and the learner said "no rollout data" after each one.
  void learnerWasBusy(Clock::duration d);

  // Seconds since the last accepted chunk (or since the start, when none came yet).
  double silentFor(Clock::time_point now) const;

 private:
  struct Heard {
    Clock::time_point last;
    int64_t chunks = 0;
  };
  double warn_after_s_;
  Clock::time_point last_data_, last_warning_;
  bool warned_ = false;
  int64_t dropped_at_last_data_ = -1;  // -1: not yet known (set on the first check)
  std::map<int, Heard> actors_;
};

}  // namespace masa::learner
