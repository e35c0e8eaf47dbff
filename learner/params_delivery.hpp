// Does every live actor hold the learner's newest parameters, and if not, when should the learner
// send them again? On a lossy LAN a parameter broadcast is lost whole when any of its LCM fragments
// is (215 KB travel as 4: at 20% datagram loss more than half of the broadcasts), and an actor that
// missed one waits, then simulates a rollout the learner drops as too old, until the periodic
// repeat (runner.republish_every_s, 1 s) reaches it (issue #33; docs/reliability.md "A lossy LAN").
//
// So actors acknowledge: a heartbeat whenever parameters reach them names the newest version they
// hold, and a chunk acted with a version shows it too. The learner repeats a version that a live
// actor has not acknowledged, first after first_repeat_s, then at 1.5x the interval each time, up
// to max_repeat_s: a lost broadcast costs one short interval, and a dead actor (or one whose
// acknowledgements are lost) costs a few repeats, not a flood. Not 2x: at 20% loss a 4-fragment
// broadcast is lost 6 times in 10 (1 - 0.8^4), so third and fourth tries are common, and doubling
// would have them wait 4x and 8x the first interval. An actor is live while it was heard
// within live_s. An actor holding another version than the learner's (the learner resumed from an
// older checkpoint) has not acknowledged it either: the repeats bring its take-back sooner.
//
// Only what passed the run key, the wire guard and the learner's checks is reported here. Pure
// bookkeeping over the times it is given: tested without a clock.
#pragma once

#include <chrono>
#include <cstdint>
#include <vector>

namespace masa::learner {

class ParamsDelivery {
 public:
  using Clock = std::chrono::steady_clock;

  // first_repeat_s <= 0: never repeat for acknowledgements (only the periodic republish).
  ParamsDelivery(double first_repeat_s, double max_repeat_s, double live_s);

  // The learner broadcast `version`. A new version starts the intervals again from first_repeat_s;
  // another broadcast of the same version makes the next one 1.5x longer.
  void published(int64_t version, Clock::time_point now);
  // A valid message of actor `actor_id` (0 <= id, below the learner's bound) says it holds `version`.
  void actorHolds(int actor_id, int64_t version, Clock::time_point now);

  // A live actor has not acknowledged the latest broadcast's version, and its interval is over.
  bool repeatDue(Clock::time_point now) const { return now >= nextRepeat(now); }
  // When repeatDue() turns true by time alone; Clock::time_point::max() when nobody is waited for.
  Clock::time_point nextRepeat(Clock::time_point now) const;
  // Actors that have said what they hold, ever (the learner reports it at exit).
  int knownActors() const;

 private:
  struct ActorState {
    int64_t holds = -1;
    Clock::time_point heard{};
    bool known = false;
  };

  Clock::duration first_, max_, live_;
  std::vector<ActorState> actors_;  // indexed by actor id
  int64_t version_ = -1;            // of the latest broadcast
  Clock::time_point last_publish_{};
  Clock::duration interval_{};
};

}  // namespace masa::learner
