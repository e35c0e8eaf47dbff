// How the runner's process is scheduled on the robot's computer (config section realtime:): pinned
// to one core, at a real-time priority, with its memory locked. A setting the system does not
// permit (no root or CAP_SYS_NICE, a core that does not exist) is said and skipped, not fatal:
// the runner still works, with a worse latency tail.
#pragma once

#include <string>

namespace masa::deploy {

struct RealtimeSettings {
  int cpu = -1;        // core to pin every thread to; -1: any
  int priority = 0;    // SCHED_FIFO priority 1..99; 0: the normal scheduler
  bool lock_memory = false;  // mlockall: no page fault in the control loop
};

// Applies `s` to the calling process; call it before starting threads (LCM's receive thread
// inherits the affinity and the policy). Returns what was applied, and what not and why.
std::string applyRealtime(const RealtimeSettings& s);

}  // namespace masa::deploy
