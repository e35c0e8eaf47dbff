// A configuration built in layers over its defaults file, which is also its schema (and so the one
// place a default is stated): each layer (a task file, a recipe, a config file, a command-line
// `key.path=value`) may set only keys the schema has, with the schema's shape (a value where a value
// belongs, a list where a list, a map where a map). An unknown key is an error naming the file and
// the key path and listing the keys known there. Every key remembers the layer that set it, so that
// ConfigSection's errors name it.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/core/config_section.hpp"

namespace masa::config {

inline constexpr const char* kCommandLine = "command line";

struct SchemaRules {
  // Key paths whose contents the schema does not list (a run's env): merged key by key, checked by
  // their own reader.
  std::vector<std::string> open_sections;
  // Keys renamed since files were first written: old full path -> new key in the same section.
  std::map<std::string, std::string> renamed;
};

class ConfigLayers {
 public:
  ConfigLayers(const YAML::Node& schema, std::string schema_file, SchemaRules rules = {});

  // A layer read from `file` (empty or null: nothing).
  void overlay(const YAML::Node& layer, const std::string& file);
  // One command-line setting, checked like a file's key.
  void set(const std::string& path, const YAML::Node& value);

  const YAML::Node& tree() const { return tree_; }
  const Origins& origin() const { return origin_; }
  const std::string& schemaFile() const { return schema_file_; }
  ConfigSection section(const std::string& prefix = "") const;

 private:
  void overlayAt(YAML::Node dst, const YAML::Node& src, const YAML::Node& schema, const std::string& path,
                 const std::string& file);
  bool isOpen(const std::string& path) const;

  YAML::Node schema_, tree_;
  std::string schema_file_;
  SchemaRules rules_;
  Origins origin_;
};

// A YAML file; a missing file or a syntax error (with its line) is a ConfigError naming `path`, the
// first with `key_for_missing` as the key.
YAML::Node loadYamlFile(const std::string& path, const std::string& key_for_missing = "(file)");
// "a.b=value" (value in YAML: 1e-4, true, [256, 128], elu) as (path, value); ConfigError otherwise.
std::pair<std::string, YAML::Node> parseSetting(const std::string& setting);

}  // namespace masa::config
