// Typed reader of a task's `env` section. The task asks for every parameter it knows (with its
// default); finish() then rejects any key it never asked for, so a misspelt reward weight is an
// error naming the file and the key instead of a silently ignored setting.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

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
  YAML::Node lookup(const std::string& path) const;
  std::string originOf(const std::string& path) const;

  YAML::Node env_;
  std::map<std::string, std::string> origin_;
  std::string default_origin_;
  std::set<std::string> asked_;
};

}  // namespace masa::task
