// The error for bad input files: always names the file and the key, so a user can fix it.
#pragma once

#include <stdexcept>
#include <string>

namespace masa {

class ConfigError : public std::runtime_error {
 public:
  ConfigError(const std::string& file, const std::string& key, const std::string& what)
      : std::runtime_error(file + ": key '" + key + "': " + what), file_(file), key_(key) {}
  const std::string& file() const { return file_; }
  const std::string& key() const { return key_; }

 private:
  std::string file_;
  std::string key_;
};

}  // namespace masa
