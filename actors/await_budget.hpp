// How long an actor waits, after publishing a rollout, for parameters newer than those it acted
// with: at least the configured wait, and 1.5x the learner's recent answer time (a moving average
// of the time from a rollout's end to the next parameters) up to a bound. A learner whose updates
// outlast the configured wait (a big batch, a loaded machine) would otherwise receive rollouts of
// an old policy that it must drop. Pure arithmetic: tested without a clock.
#pragma once

#include <algorithm>

namespace masa::actor {

class AwaitBudget {
 public:
  // base_s <= 0: never wait.
  AwaitBudget(double base_s, double max_s) : base_s_(base_s), max_s_(max_s) {}

  // The learner answered a rollout after `delay_s` seconds.
  void observeAnswer(double delay_s) {
    learner_delay_s_ = learner_delay_s_ > 0 ? 0.7 * learner_delay_s_ + 0.3 * delay_s : delay_s;
  }
  double learnerDelaySeconds() const { return learner_delay_s_; }

  double limitSeconds() const {
    if (base_s_ <= 0) return 0.0;
    return std::max(base_s_, std::min(max_s_, 1.5 * learner_delay_s_));
  }

 private:
  double base_s_, max_s_;
  double learner_delay_s_ = 0;
};

}  // namespace masa::actor
