// The link between the runner and masa_sim_robot as a real one may be: each state or command
// message lost with a probability, each command delivered after a delay plus a uniform jitter (so
// commands may arrive out of order). One seeded generator draws all of it, in the order the
// messages come, so a seed gives the same faults for the same traffic.
#pragma once

#include <cstdint>
#include <deque>
#include <random>

#include "masa/lcmt_robot_command.hpp"

namespace masa::deploy {

class CommandLink {
 public:
  CommandLink(double loss, double delay_ms, double jitter_ms, uint64_t seed);

  // A state message about to go out: is it lost? (counted)
  bool loseState();
  // A command just received at wall time now_s: lost (counted; returns false), or queued for its
  // delivery time (returns true).
  bool receive(const masa::lcmt_robot_command& cmd, double now_s);
  // Before the first command: the delivered commands in queue order; false while none is due.
  bool takeInOrder(double now_s, masa::lcmt_robot_command& cmd);
  // In control: of the commands due by now_s, the newest (by utime) replaces cmd if not older.
  void takeNewest(double now_s, masa::lcmt_robot_command& cmd);

  int64_t lostCommands() const { return lost_commands_; }
  int64_t lostStates() const { return lost_states_; }

 private:
  struct Pending {
    double deliver_at_s;
    masa::lcmt_robot_command cmd;
  };
  bool lose() { return loss_ > 0 && unit_(rng_) < loss_; }

  double loss_, delay_s_, jitter_s_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
  std::deque<Pending> pending_;
  int64_t lost_commands_ = 0, lost_states_ = 0;
};

}  // namespace masa::deploy
