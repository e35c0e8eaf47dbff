#include "learner/ppo/adaptive_lr.hpp"

#include <algorithm>

#include "common/core/check.hpp"

namespace masa::ppo {

LrSchedule parseLrSchedule(const std::string& name) {
  if (name == "adaptive") return LrSchedule::kAdaptive;
  if (name == "fixed") return LrSchedule::kFixed;
  MASA_CHECK(false, "unknown lr_schedule '" << name << "' (expected adaptive or fixed)");
  return LrSchedule::kFixed;
}

AdaptiveLr::AdaptiveLr(LrSchedule schedule, double lr, double kl_threshold, double lr_min, double lr_max)
    : schedule_(schedule), lr_(lr), kl_threshold_(kl_threshold), lr_min_(lr_min), lr_max_(lr_max) {
  MASA_CHECK(lr > 0 && lr_min > 0 && lr_min <= lr_max, "learning rate " << lr << " with bounds [" << lr_min << ", "
                                                                        << lr_max << "]");
  MASA_CHECK(schedule == LrSchedule::kFixed || kl_threshold > 0, "kl_threshold must be positive, got " << kl_threshold);
}

double AdaptiveLr::update(double kl) {
  if (schedule_ == LrSchedule::kFixed) return lr_;
  if (kl > 2.0 * kl_threshold_) lr_ = std::max(lr_ / 1.5, lr_min_);
  if (kl < 0.5 * kl_threshold_) lr_ = std::min(lr_ * 1.5, lr_max_);
  return lr_;
}

}  // namespace masa::ppo
