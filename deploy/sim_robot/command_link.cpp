#include "deploy/sim_robot/command_link.hpp"

namespace masa::deploy {

CommandLink::CommandLink(double loss, double delay_ms, double jitter_ms, uint64_t seed)
    : loss_(loss), delay_s_(1e-3 * delay_ms), jitter_s_(1e-3 * jitter_ms), rng_(seed) {}

bool CommandLink::loseState() {
  if (!lose()) return false;
  ++lost_states_;
  return true;
}

bool CommandLink::receive(const masa::lcmt_robot_command& cmd, double now_s) {
  if (lose()) {
    ++lost_commands_;
    return false;
  }
  pending_.push_back({now_s + delay_s_ + jitter_s_ * unit_(rng_), cmd});
  return true;
}

bool CommandLink::takeInOrder(double now_s, masa::lcmt_robot_command& cmd) {
  bool took = false;
  while (!pending_.empty() && pending_.front().deliver_at_s <= now_s) {
    cmd = pending_.front().cmd;
    pending_.pop_front();
    took = true;
  }
  return took;
}

void CommandLink::takeNewest(double now_s, masa::lcmt_robot_command& cmd) {
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (it->deliver_at_s <= now_s) {
      if (it->cmd.utime >= cmd.utime) cmd = it->cmd;
      it = pending_.erase(it);
    } else {
      ++it;
    }
  }
}

}  // namespace masa::deploy
