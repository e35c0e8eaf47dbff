// Typed reader of a task's `env` section. The task asks for every parameter it knows (with its
// default); finish() then rejects any key it never asked for, so a misspelt reward weight is an
// error naming the file and the key instead of a silently ignored setting. The reads themselves
// (types, finiteness, ranges, the error's file and key path) are the run config's reader's
// (common/core/config_section.hpp): one reader, one error format.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/core/config_section.hpp"

namespace masa::task {

class EnvParams {
 public:
  // origin maps "env.<key>" paths to the file (or "command line") that set them.
  EnvParams(YAML::Node env, std::map<std::string, std::string> origin = {}, std::string default_origin = "configs");

  double number(const std::string& key, double fallback);
  double positive(const std::string& key, double fallback);
  int integer(const std::string& key, int fallback, int min_value);
  bool flag(const std::string& key, bool fallback);
  std::string text(const std::string& key, const std::string& fallback);
  // The reward weight of `term`, from env.weights.<term>.
  double weight(const std::string& term, double fallback);
  // A whole sub-tree (a list or mapping), undefined when absent; the caller validates what is inside
  // (finish() no longer looks into it). origin() names the file that set a key, for its errors.
  YAML::Node section(const std::string& key);
  std::string origin(const std::string& key) const { return originOf(key); }

  void finish() const;  // throws ConfigError for keys never asked for

 private:
  // The value at `key` when a layer gave one (not null), after noting that the task knows the key.
  bool given(const std::string& key);
  std::string originOf(const std::string& key) const { return reader_.originOf(key); }

  YAML::Node env_;
  config::ConfigSection reader_;  // over {env: env_}, at "env"
  std::set<std::string> asked_;
};

}  // namespace masa::task
