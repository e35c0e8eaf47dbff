// A fresh, empty folder under the system's temporary directory, unique to this test process.
#pragma once

#include <filesystem>
#include <string>

#include <unistd.h>

namespace masa::testing {

inline std::filesystem::path freshTempDir(const std::string& name) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace masa::testing
