#include "common/core/shell_quoted.hpp"

namespace masa {

std::string shellQuoted(std::string_view s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}

}  // namespace masa
