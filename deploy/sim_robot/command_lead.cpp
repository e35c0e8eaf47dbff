#include "deploy/sim_robot/command_lead.hpp"

#include <stdexcept>

namespace masa::deploy {

CommandLead::CommandLead(int64_t max_lead_us) : max_lead_us_(max_lead_us) {
  if (max_lead_us < 0) throw std::invalid_argument("CommandLead: max_lead_us >= 0");
}

bool CommandLead::admits(int64_t utime, int64_t now_us) {
  // 128 bits: a hostile utime may be anything, and int64 sums overflow.
  if (static_cast<__int128>(utime) <= static_cast<__int128>(now_us) + max_lead_us_) return true;
  ++refused_;
  return false;
}

}  // namespace masa::deploy
