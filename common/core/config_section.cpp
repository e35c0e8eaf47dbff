#include "common/core/config_section.hpp"

#include <sstream>

namespace masa::config {

std::string formatNumber(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

void failAt(const std::string& file, const std::string& path, const YAML::Node& node, std::string what) {
  if (node.IsDefined() && !node.Mark().is_null()) what += " (line " + std::to_string(node.Mark().line + 1) + ")";
  throw ConfigError(file, path, what);
}

ConfigSection::ConfigSection(YAML::Node root, Origins origin, std::string default_file, std::string prefix)
    : root_(std::move(root)), origin_(std::move(origin)), default_file_(std::move(default_file)), prefix_(std::move(prefix)) {}

ConfigSection ConfigSection::section(const std::string& key) const {
  return ConfigSection(root_, origin_, default_file_, path(key));
}

std::string ConfigSection::path(const std::string& key) const { return prefix_.empty() ? key : prefix_ + "." + key; }

std::string ConfigSection::originOf(const std::string& key) const {
  // The key itself, else the nearest enclosing map that a layer set as a whole.
  for (std::string p = path(key);; p.resize(p.rfind('.'))) {
    if (const auto it = origin_.find(p); it != origin_.end()) return it->second;
    if (p.find('.') == std::string::npos) return default_file_;
  }
}

YAML::Node ConfigSection::node(const std::string& key) const {
  YAML::Node n;
  n.reset(root_);  // reset() rebinds; operator= would overwrite the node's contents
  std::stringstream ss(path(key));
  for (std::string part; std::getline(ss, part, '.');) {
    if (!n.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
    const YAML::Node next = n[part];
    // A missing key: an undefined node, never the zombie yaml-cpp returns (reading it throws
    // InvalidNode, which names no file).
    if (!next.IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
    n.reset(next);
  }
  return n;
}

double ConfigSection::positive(const std::string& key) const {
  const double v = number(key);
  if (!(v > 0)) fail(key, "must be positive, got " + formatNumber(v));
  return v;
}

double ConfigSection::nonNegative(const std::string& key) const {
  const double v = number(key);
  if (!(v >= 0)) fail(key, "must not be negative, got " + formatNumber(v));
  return v;
}

double ConfigSection::inRange(const std::string& key, double lo, double hi, bool open_lo, bool open_hi) const {
  const double v = number(key);
  const bool above = open_lo ? v > lo : v >= lo;
  const bool below = open_hi ? v < hi : v <= hi;
  if (!(above && below))
    fail(key, std::string("must be in ") + (open_lo ? "(" : "[") + formatNumber(lo) + ", " + formatNumber(hi) +
                  (open_hi ? ")" : "]") + ", got " + formatNumber(v));
  return v;
}

int ConfigSection::integerIn(const std::string& key, int lo, int hi) const {
  const int v = get<int>(key, "an integer");  // "1.5" is not one
  if (v < lo || v > hi)
    fail(key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + std::to_string(v));
  return v;
}

std::vector<int> ConfigSection::widths(const std::string& key, bool allow_empty) const {
  const auto v = get<std::vector<int>>(key, "a list of integers");
  if (v.empty() && !allow_empty) fail(key, "needs at least one layer width");
  for (int w : v)
    if (w < 1) fail(key, "layer widths must be positive, got " + std::to_string(w));
  return v;
}

std::string ConfigSection::oneOf(const std::string& key, const std::vector<std::string>& choices) const {
  std::string listed;
  for (size_t i = 0; i < choices.size(); ++i)
    listed += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + choices[i];
  const std::string v = get<std::string>(key, listed);
  for (const std::string& c : choices)
    if (v == c) return v;
  fail(key, "expected " + listed + ", got '" + v + "'");
}

void ConfigSection::fail(const std::string& key, const std::string& what) const {
  failAt(originOf(key), path(key), node(key), what);
}

}  // namespace masa::config
