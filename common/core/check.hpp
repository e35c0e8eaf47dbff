// Always-on precondition checks (kept in release builds: a wrong size or index must fail loudly
// where it happens, never corrupt a batch silently).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace masa::detail {
[[noreturn]] inline void checkFailed(const char* expr, const char* file, int line, const std::string& msg) {
  std::ostringstream os;
  os << file << ":" << line << ": check failed: " << expr;
  if (!msg.empty()) os << ": " << msg;
  throw std::invalid_argument(os.str());
}
}  // namespace masa::detail

// MASA_CHECK(cond, "message " << value): throws std::invalid_argument naming the place and cause.
#define MASA_CHECK(cond, ...)                                                          \
  do {                                                                                 \
    if (!(cond)) {                                                                     \
      std::ostringstream masa_check_os_;                                               \
      masa_check_os_ << __VA_ARGS__;                                                   \
      ::masa::detail::checkFailed(#cond, __FILE__, __LINE__, masa_check_os_.str());    \
    }                                                                                  \
  } while (false)
