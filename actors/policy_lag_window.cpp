#include "actors/policy_lag_window.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace masa::actor {

PolicyLagWindow::PolicyLagWindow(int max_policy_lag) : lag_(max_policy_lag) {
  if (max_policy_lag < 0) throw std::invalid_argument("max_policy_lag must be >= 0, got " + std::to_string(max_policy_lag));
}

void PolicyLagWindow::sent(int64_t version, double end_s) {
  int64_t ahead = 0;  // rollouts the learner takes before this one
  for (const Sent& s : window_) ahead += s.answered ? 0 : 1;
  window_.push_back({version + 1 + std::min<int64_t>(ahead, lag_), end_s, false});
  while (window_.size() > static_cast<std::size_t>(lag_) + 1) {
    // A rollout leaves the window unanswered when the actor gave up waiting for its answer. The
    // actor has been waiting since its end: the rollout behind it keeps that time, so the answer
    // says how long the learner really took. Measured from the newer rollout's end instead, a
    // timed-out wait looked like a quick answer, the budget shrank and more waits timed out: with
    // a learner slower than its actors, each actor sent rollouts it would drop (16-core machine,
    // 15 actors: 1000 of them per update).
    if (!window_.front().answered) window_[1].waiting_since_s = std::min(window_[1].waiting_since_s, window_.front().waiting_since_s);
    window_.pop_front();
  }
}

int64_t PolicyLagWindow::neededVersion() const {
  // The rollout lag_ + 1 back must have been answered: then the next one, acted with its answer,
  // is at most lag_ versions behind the learner when it arrives.
  if (window_.size() < static_cast<std::size_t>(lag_) + 1) return -1;
  return window_.front().answered_by;
}

std::optional<double> PolicyLagWindow::answer(int64_t version, double now_s) {
  for (Sent& s : window_) {  // oldest first
    if (s.answered || version < s.answered_by) continue;
    s.answered = true;
    return now_s - s.waiting_since_s;
  }
  return std::nullopt;
}

}  // namespace masa::actor
