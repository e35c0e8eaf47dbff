// A fresh run never writes over another run. A run directory that already holds a run's state or
// its metrics is refused before anything is written: a rerun with the same --run-dir would
// otherwise overwrite the old checkpoint (what a resume needs) and add a second run's rows to the
// old metrics.csv, whose curve would then be nonsense. Files of the launchers (roster, keys, logs)
// do not count: they are written before the learner starts.
#pragma once

#include <cstdint>
#include <string>

namespace masa::learner {

// Throws std::runtime_error naming the directory, what it holds, and the two ways on (--resume, or
// another directory) when `dir` holds checkpoint.bin, sac_state.bin, off_policy_state.bin or a
// non-empty metrics.csv. A missing or empty directory passes.
void refuseRunDirInUse(const std::string& dir);

// A new run's directory when none is given: runs/<name>_<seed>_<local time YYYYmmdd-HHMMSS>, so that
// running the same command again starts a new run beside the last one instead of being refused.
std::string defaultRunDir(const std::string& name, uint64_t seed);

}  // namespace masa::learner
