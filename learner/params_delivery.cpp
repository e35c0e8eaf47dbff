#include "learner/params_delivery.hpp"

#include <algorithm>

#include "common/core/check.hpp"

namespace masa::learner {
namespace {

ParamsDelivery::Clock::duration seconds(double s) {
  return std::chrono::duration_cast<ParamsDelivery::Clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

ParamsDelivery::ParamsDelivery(double first_repeat_s, double max_repeat_s, double live_s)
    : first_(seconds(first_repeat_s)), max_(seconds(std::max(max_repeat_s, first_repeat_s))), live_(seconds(live_s)) {}

void ParamsDelivery::published(int64_t version, Clock::time_point now) {
  if (version != version_) {
    version_ = version;
    interval_ = first_;
  } else {
    interval_ = std::min(interval_ + interval_ / 2, max_);
  }
  last_publish_ = now;
}

void ParamsDelivery::actorHolds(int actor_id, int64_t version, Clock::time_point now) {
  MASA_CHECK(actor_id >= 0, "params delivery: actor " << actor_id);
  if (actor_id >= static_cast<int>(actors_.size())) actors_.resize(actor_id + 1);
  ActorState& a = actors_[actor_id];
  // A chunk acted with an older version may arrive after the heartbeat that acknowledged the
  // newest: an acknowledgement of the latest broadcast stands until the next version.
  if (!(a.holds == version_ && version < version_)) a.holds = version;
  a.heard = now;
  a.known = true;
}

ParamsDelivery::Clock::time_point ParamsDelivery::nextRepeat(Clock::time_point now) const {
  if (first_ <= Clock::duration::zero() || version_ < 0) return Clock::time_point::max();
  for (const ActorState& a : actors_)
    if (a.known && a.holds != version_ && now - a.heard <= live_) return last_publish_ + interval_;
  return Clock::time_point::max();
}

int ParamsDelivery::knownActors() const {
  int n = 0;
  for (const ActorState& a : actors_) n += a.known ? 1 : 0;
  return n;
}

}  // namespace masa::learner
