#include "common/sim/yaml/yaml_fields.hpp"

#include <algorithm>

#include "common/core/config_error.hpp"

namespace masa::task {

YamlFields::YamlFields(const YAML::Node& node, std::string path, std::string file,
                       const std::vector<std::string>& allowed)
    : node_(node), path_(std::move(path)), file_(std::move(file)) {
  std::string valid;
  for (const std::string& a : allowed) valid += (valid.empty() ? "" : ", ") + a;
  if (!node_.IsMap()) failAt(file_, path_, node_, "expected a mapping with keys " + valid);
  for (const auto& kv : node_) {
    const std::string key = kv.first.Scalar();
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
      failAt(file_, pathOf(key), kv.first, "unknown key; valid keys here: " + valid);
  }
}

void YamlFields::fail(const std::string& key, const std::string& what) const {
  failAt(file_, key.empty() ? path_ : pathOf(key), key.empty() ? node_ : node_[key], what);
}

bool YamlFields::has(const std::string& key) const { return node_[key].IsDefined() && !node_[key].IsNull(); }

std::string YamlFields::text(const std::string& key) const {
  if (!has(key)) fail("", "missing required key '" + key + "'");
  const YAML::Node n = node_[key];
  if (!n.IsScalar() || n.Scalar().empty()) fail(key, "expected a non-empty string");
  return n.Scalar();
}

std::string YamlFields::text(const std::string& key, const std::string& fallback) const {
  return has(key) ? text(key) : fallback;
}

double YamlFields::number(const std::string& key) const {
  if (!has(key)) fail("", "missing required key '" + key + "'");
  return config::readValue<double>(node_[key], file_, pathOf(key), "a number");
}

double YamlFields::number(const std::string& key, double fallback) const {
  return has(key) ? number(key) : fallback;
}

}  // namespace masa::task
