// A directory named by an environment variable (MASA_CONFIGS, MASA_ROOT), checked where it is read:
// a variable set to a file, a typo or nothing at all would otherwise surface as a missing config
// or model file far from its cause, naming neither the variable nor its value.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

#include "common/core/config_error.hpp"

namespace masa {

inline std::string directoryFromEnvironment(const char* variable, const std::string& fallback) {
  const char* value = std::getenv(variable);
  if (value == nullptr) return fallback;
  std::error_code ec;
  if (*value == '\0' || !std::filesystem::is_directory(value, ec))
    throw ConfigError("(environment)", variable,
                      "'" + std::string(value) + "' is not a directory (unset it to use " + fallback + ")");
  return value;
}

}  // namespace masa
