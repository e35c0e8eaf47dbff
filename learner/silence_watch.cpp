#include "learner/silence_watch.hpp"

#include <cstdio>

namespace masa::learner {

namespace {
double seconds(SilenceWatch::Clock::duration d) { return std::chrono::duration<double>(d).count(); }
}  // namespace

SilenceWatch::SilenceWatch(double warn_after_s, Clock::time_point start)
    : warn_after_s_(warn_after_s), last_data_(start), last_warning_(start) {}

void SilenceWatch::heard(int actor_id, Clock::time_point now) {
  Heard& h = actors_[actor_id];
  h.last = now;
  ++h.chunks;
  last_data_ = now;
  warned_ = false;
  dropped_at_last_data_ = -1;
}

void SilenceWatch::learnerWasBusy(Clock::duration d) {
  last_data_ += d;
  last_warning_ += d;
}

double SilenceWatch::silentFor(Clock::time_point now) const { return seconds(now - last_data_); }

std::optional<std::string> SilenceWatch::check(Clock::time_point now, int64_t update, int64_t dropped_chunks) {
  if (dropped_at_last_data_ < 0) dropped_at_last_data_ = dropped_chunks;
  if (warn_after_s_ <= 0) return std::nullopt;
  const double silent = seconds(now - last_data_);
  if (silent < warn_after_s_) return std::nullopt;
  if (warned_ && seconds(now - last_warning_) < warn_after_s_) return std::nullopt;
  warned_ = true;
  last_warning_ = now;
  char buf[160];
  std::snprintf(buf, sizeof buf, "masa_learner: no rollout data for %.0f s (at update %lld); ", silent,
                static_cast<long long>(update));
  std::string text = buf;
  if (actors_.empty()) {
    text += "no actor heard from yet (are the actors running, with this learner's --url and run id?)";
  } else {
    text += "last heard from";
    const char* sep = " ";
    for (const auto& [id, h] : actors_) {
      std::snprintf(buf, sizeof buf, "%sactor %d %.0f s ago (%lld chunks)", sep, id, seconds(now - h.last),
                    static_cast<long long>(h.chunks));
      text += buf;
      sep = ", ";
    }
  }
  const int64_t dropped = dropped_chunks - dropped_at_last_data_;
  if (dropped > 0) {
    std::snprintf(buf, sizeof buf, "; %lld chunks dropped meanwhile (see the drop counts: another run or config?)",
                  static_cast<long long>(dropped));
    text += buf;
  }
  return text;
}

}  // namespace masa::learner
