#include "common/model/method.hpp"

#include <algorithm>
#include <stdexcept>

namespace masa::model {

Method parseMethod(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return std::tolower(c); });
  if (n == "masa") return Method::kMasa;
  if (n == "sa") return Method::kSa;
  if (n == "sasa") return Method::kSasa;
  if (n == "ma") return Method::kMa;
  throw std::invalid_argument("unknown method '" + name + "' (expected one of: masa, sa, sasa, ma)");
}

std::string methodName(Method m) {
  switch (m) {
    case Method::kMasa: return "masa";
    case Method::kSa: return "sa";
    case Method::kSasa: return "sasa";
    case Method::kMa: return "ma";
  }
  return "?";
}

}  // namespace masa::model
