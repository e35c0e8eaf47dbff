// rl_games' KL-adaptive learning rate ('legacy' placement: updated after every minibatch from that
// minibatch's KL). 'fixed' keeps the learning rate it was given.
#pragma once

#include <string>

namespace masa::ppo {

enum class LrSchedule { kAdaptive, kFixed };

LrSchedule parseLrSchedule(const std::string& name);  // "adaptive" | "fixed"; throws otherwise

class AdaptiveLr {
 public:
  AdaptiveLr(LrSchedule schedule, double lr, double kl_threshold, double lr_min, double lr_max);

  // kl > 2 threshold: lr = max(lr / 1.5, lr_min); kl < threshold / 2: lr = min(lr * 1.5, lr_max).
  // Returns the new learning rate.
  double update(double kl);

  double lr() const { return lr_; }
  void setLr(double lr) { lr_ = lr; }  // e.g. restored from a checkpoint
  LrSchedule schedule() const { return schedule_; }

 private:
  LrSchedule schedule_;
  double lr_, kl_threshold_, lr_min_, lr_max_;
};

}  // namespace masa::ppo
