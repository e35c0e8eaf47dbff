// Reading one mapping of a hand-written YAML file with errors a user can act on: every key must be
// one the reader knows (a typo is an error listing the valid keys, never a silent default), and
// every error names the file, the key path and the line. Values are read as the run config's are
// (config::readValue: types, finiteness, one error format).
#pragma once

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/core/config_section.hpp"

namespace masa::task {

class YamlFields {
 public:
  // `node` must be a mapping whose keys are all in `allowed`; `path` is its key path for errors
  // ("env.reward.up"), `file` the file (or "command line") it came from.
  YamlFields(const YAML::Node& node, std::string path, std::string file, const std::vector<std::string>& allowed);

  bool has(const std::string& key) const;
  std::string text(const std::string& key) const;  // required
  std::string text(const std::string& key, const std::string& fallback) const;
  double number(const std::string& key) const;  // required
  double number(const std::string& key, double fallback) const;
  YAML::Node node(const std::string& key) const { return node_[key]; }
  std::string pathOf(const std::string& key) const { return path_ + "." + key; }
  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }

  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  YAML::Node node_;
  std::string path_, file_;
};

// The error for `node` at `path` of `file`, with the node's line when it has one: the config
// reader's (common/core/config_section.hpp).
using config::failAt;

}  // namespace masa::task
