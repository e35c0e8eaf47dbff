// A command may not claim a time further ahead of the robot's own clock than a bound (issue #55,
// item 2). The robot applies the newest command by utime (command_link.hpp), so one command
// stamped far in the future, from anyone who can publish on the command channel (or a runner with
// a wrong clock), would win over every later real command and pin the robot to its targets. A
// runner stamps its commands with its wall clock; the bound covers the two clocks' disagreement
// (NTP on one LAN: milliseconds) and the network's delay, which only makes a command look older.
#pragma once

#include <cstdint>

namespace masa::deploy {

class CommandLead {
 public:
  // max_lead_us >= 0: how far a command's utime may be ahead of the robot's clock.
  explicit CommandLead(int64_t max_lead_us);

  // Whether a command stamped `utime` (the runner's wall clock), received when the robot's wall
  // clock reads `now_us`, may be taken; a refusal is counted.
  bool admits(int64_t utime, int64_t now_us);

  int64_t refused() const { return refused_; }
  int64_t maxLeadUs() const { return max_lead_us_; }

 private:
  int64_t max_lead_us_;
  int64_t refused_ = 0;
};

}  // namespace masa::deploy
