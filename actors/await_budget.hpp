// How long an actor waits, after publishing a rollout, for parameters newer than those it acted
// with: the configured wait until the learner has answered once, then 1.5x the learner's recent
// answer time (a moving average of the time from a rollout's end to the next parameters), between
// a floor and a bound. Longer than the configured wait: a learner whose updates outlast it (a big
// batch, a loaded machine) would otherwise receive rollouts of an old policy that it must drop.
// Shorter: when a chunk is lost the learner cannot complete its batch and says nothing, and every
// actor waited the whole configured second before sending the environments that replace it (at 5%
// loss, 0.15 of the lossless update rate on the namespace LAN; bench/e2e_loss.sh).
// Pure arithmetic: tested without a clock.
#pragma once

#include <algorithm>

namespace masa::actor {

class AwaitBudget {
 public:
  // base_s <= 0: never wait.
  AwaitBudget(double base_s, double max_s, double min_s = 0.02) : base_s_(base_s), max_s_(max_s), min_s_(min_s) {}

  // The learner answered a rollout after `delay_s` seconds.
  void observeAnswer(double delay_s) {
    learner_delay_s_ = learner_delay_s_ > 0 ? 0.7 * learner_delay_s_ + 0.3 * delay_s : delay_s;
  }
  double learnerDelaySeconds() const { return learner_delay_s_; }

  // A wait ended without the parameters it waited for. Before any answer was measured the learner's
  // first update may simply outlast the configured wait (a big batch: 9 s for 15 actors on one
  // learner core on the 16-core machine), and each actor then sent a stale rollout every second
  // until it ended: the next wait is twice as long, up to the bound. Once answers are measured the
  // answer times (PolicyLagWindow keeps the time since the rollout waited on) set the wait.
  void observeTimeout() {
    if (learner_delay_s_ <= 0 && base_s_ > 0) base_s_ = std::min(2.0 * base_s_, max_s_);
  }

  double limitSeconds() const {
    if (base_s_ <= 0) return 0.0;
    if (learner_delay_s_ <= 0) return base_s_;  // not measured yet
    return std::clamp(1.5 * learner_delay_s_, std::min(min_s_, max_s_), max_s_);
  }

 private:
  double base_s_, max_s_, min_s_;
  double learner_delay_s_ = 0;
};

}  // namespace masa::actor
