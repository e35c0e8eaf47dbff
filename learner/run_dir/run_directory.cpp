#include "learner/run_dir/run_directory.hpp"

#include <ctime>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace fs = std::filesystem;

namespace masa::learner {

void refuseRunDirInUse(const std::string& dir) {
  // The state files of the three learners (PPO's, masa_sac's, the off-policy learner's), then the
  // metrics every one of them writes.
  for (const char* name : {"checkpoint.bin", "sac_state.bin", "off_policy_state.bin", "metrics.csv"}) {
    const fs::path path = fs::path(dir) / name;
    std::error_code ec;
    const bool exists = fs::exists(path, ec);
    if (ec || !exists) continue;
    if (std::string(name) == "metrics.csv" && fs::file_size(path, ec) == 0 && !ec) continue;
    throw std::runtime_error("run directory '" + dir + "' already holds a run (" + name + "): go on with it (--resume " +
                             dir + "), or give the new run another directory (starting here would overwrite that " +
                             "run's state and mix two runs in its metrics.csv)");
  }
}

std::string defaultRunDir(const std::string& name, uint64_t seed) {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", &tm);
  return "runs/" + name + "_" + std::to_string(seed) + "_" + stamp;
}

}  // namespace masa::learner
