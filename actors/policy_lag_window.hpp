// Which parameters an actor needs before its next rollout, given that the learner accepts rollouts
// acted with a policy up to ppo.max_policy_lag versions old. With lag 0 the actor waits for the
// answer to its last rollout: strictly on-policy, actors and learner take turns, and on cores of
// their own each idles while the other works. With lag L it may have L rollouts unanswered, so it
// collects the next rollout while the learner learns from the last one: the update's time hides
// behind the rollout's (docs/scaling.md), and every rollout still reaches the learner within the lag.
// Each update takes one rollout of every actor, so a rollout is answered not by the next version
// after the one it acted with but by the version of the update that takes it: the one it acted
// with, plus one, plus the actor's rollouts still unanswered when it began (the learner takes them
// first; at most the lag of them count). A rollout lost on the way shifts that count by one for
// the rollouts behind it: the actor then waits one update longer than needed, never too little.
// It also says how long after its end a rollout was answered: the actor's wait budget
// (AwaitBudget) learns the learner's answer time from that. Pure bookkeeping: no clock.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>

namespace masa::actor {

class PolicyLagWindow {
 public:
  explicit PolicyLagWindow(int max_policy_lag);

  // A rollout acted with `version` was published at end_s.
  void sent(int64_t version, double end_s);

  // The version the actor's parameters must reach before its next rollout (-1: none needed yet).
  int64_t neededVersion() const;

  // Parameters of `version` arrived at now_s: the seconds since the end of the oldest unanswered
  // rollout they answer (or of an older one the actor stopped waiting for), or nothing when they
  // answer none.
  std::optional<double> answer(int64_t version, double now_s);

 private:
  struct Sent {
    int64_t answered_by;     // the version of the update that takes this rollout
    double waiting_since_s;  // its end, or that of an older rollout whose answer never came
    bool answered;
  };
  int lag_;
  std::deque<Sent> window_;  // the last lag_ + 1 rollouts, oldest first
};

}  // namespace masa::actor
