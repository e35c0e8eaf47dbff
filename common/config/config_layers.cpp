#include "common/config/config_layers.hpp"

#include <filesystem>
#include <sstream>

#include "common/config/nearest_name.hpp"

namespace masa::config {
namespace {

std::string join(const std::string& prefix, const std::string& key) { return prefix.empty() ? key : prefix + "." + key; }

std::string kindName(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Map: return "a map";
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Scalar: return "a value";
    case YAML::NodeType::Null: return "empty";
    default: return "undefined";
  }
}

// Deep merge without a schema (open sections): maps merge key by key, anything else replaces.
void mergeOpen(YAML::Node dst, const YAML::Node& src, const std::string& path, const std::string& file,
               Origins& origin) {
  for (const auto& kv : src) {
    const std::string key = kv.first.as<std::string>();
    if (kv.second.IsMap() && dst[key].IsMap()) {
      mergeOpen(dst[key], kv.second, join(path, key), file, origin);
    } else {
      dst[key] = YAML::Clone(kv.second);
      origin[join(path, key)] = file;
    }
  }
}

// Names the schema's file too: when that file is damaged (cut short), the key is fine and the
// schema is what is missing it.
std::string unknownKey(const YAML::Node& schema, const std::string& key, const std::string& schema_file) {
  std::vector<std::string> known;
  std::string listed;
  for (const auto& s : schema) {
    known.push_back(s.first.as<std::string>());
    listed += (listed.empty() ? "" : ", ") + known.back();
  }
  std::string what = "unknown key (known here: " + listed + ")";
  if (const std::string near = nearestName(key, known); !near.empty()) what += "; did you mean '" + near + "'?";
  if (!schema_file.empty()) what += " (the keys are those of " + schema_file + ")";
  return what;
}

}  // namespace

ConfigLayers::ConfigLayers(const YAML::Node& schema, std::string schema_file, SchemaRules rules)
    : schema_(schema), tree_(YAML::Clone(schema)), schema_file_(std::move(schema_file)), rules_(std::move(rules)) {}

bool ConfigLayers::isOpen(const std::string& path) const {
  for (const std::string& open : rules_.open_sections)
    if (path == open || path.rfind(open + ".", 0) == 0) return true;
  return false;
}

void ConfigLayers::overlay(const YAML::Node& layer, const std::string& file) {
  if (layer.IsDefined() && !layer.IsNull()) overlayAt(tree_, layer, schema_, "", file);
}

void ConfigLayers::set(const std::string& path, const YAML::Node& value) {
  // {a: {b: value}}, overlaid, so that a setting gets exactly the checks of a file's key.
  YAML::Node wrapped;
  wrapped.reset(value);
  std::vector<std::string> parts;
  std::stringstream ss(path);
  for (std::string part; std::getline(ss, part, '.');) parts.push_back(part);
  for (auto it = parts.rbegin(); it != parts.rend(); ++it) {
    YAML::Node m(YAML::NodeType::Map);
    m[*it] = wrapped;
    wrapped.reset(m);
  }
  overlayAt(tree_, wrapped, schema_, "", kCommandLine);
}

ConfigSection ConfigLayers::section(const std::string& prefix) const {
  return ConfigSection(tree_, origin_, schema_file_, prefix);
}

void ConfigLayers::overlayAt(YAML::Node dst, const YAML::Node& src, const YAML::Node& schema, const std::string& path,
                             const std::string& file) {
  if (!src.IsMap()) throw ConfigError(file, path.empty() ? "(root)" : path, "expected a map, got " + kindName(src));
  for (const auto& kv : src) {
    std::string key = kv.first.as<std::string>();
    if (const auto renamed = rules_.renamed.find(join(path, key)); renamed != rules_.renamed.end()) key = renamed->second;
    const std::string full = join(path, key);
    const YAML::Node value = kv.second;
    if (isOpen(full)) {
      if (value.IsMap() && dst[key].IsMap()) {
        mergeOpen(dst[key], value, full, file, origin_);
      } else {
        dst[key] = YAML::Clone(value);
        origin_[full] = file;
      }
      continue;
    }
    const YAML::Node expected = schema[key];
    if (!expected) throw ConfigError(file, full, unknownKey(schema, key, schema_file_));
    if (expected.IsMap()) {
      overlayAt(dst[key], value, expected, full, file);
    } else {
      if (expected.IsSequence() && !value.IsSequence())
        throw ConfigError(file, full, "expected a list, got " + kindName(value));
      if (expected.IsScalar() && !value.IsScalar())
        throw ConfigError(file, full, "expected a value, got " + kindName(value));
      dst[key] = YAML::Clone(value);
      origin_[full] = file;
    }
  }
}

YAML::Node loadYamlFile(const std::string& path, const std::string& key_for_missing) {
  if (!std::filesystem::exists(path)) throw ConfigError(path, key_for_missing, "file not found");
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw ConfigError(path, "(syntax)", "YAML error at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
}

std::pair<std::string, YAML::Node> parseSetting(const std::string& setting) {
  const auto eq = setting.find('=');
  if (eq == std::string::npos || eq == 0) throw ConfigError(kCommandLine, setting, "expected key.path=value");
  const std::string path = setting.substr(0, eq);
  try {
    return {path, YAML::Load(setting.substr(eq + 1))};
  } catch (const YAML::Exception& e) {
    throw ConfigError(kCommandLine, path, "value is not valid YAML: " + e.msg);
  }
}

}  // namespace masa::config
