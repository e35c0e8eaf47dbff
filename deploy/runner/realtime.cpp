#include "deploy/runner/realtime.hpp"

#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

namespace masa::deploy {

std::string applyRealtime(const RealtimeSettings& s) {
  std::string said;
  const auto say = [&said](const std::string& what) { said += (said.empty() ? "" : "; ") + what; };
  if (s.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(s.cpu, &set);
    if (sched_setaffinity(0, sizeof(set), &set) == 0)
      say("pinned to core " + std::to_string(s.cpu));
    else
      say("NOT pinned to core " + std::to_string(s.cpu) + " (" + std::strerror(errno) + ")");
  }
  if (s.priority > 0) {
    sched_param p{};
    p.sched_priority = s.priority;
    if (sched_setscheduler(0, SCHED_FIFO, &p) == 0)
      say("SCHED_FIFO priority " + std::to_string(s.priority));
    else
      say("NOT real-time (SCHED_FIFO " + std::to_string(s.priority) + ": " + std::strerror(errno) +
          "; needs root or CAP_SYS_NICE)");
  }
  if (s.lock_memory) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0)
      say("memory locked");
    else
      say(std::string("memory NOT locked (") + std::strerror(errno) + ")");
  }
  return said.empty() ? "normal scheduling" : said;
}

}  // namespace masa::deploy
