#include "common/sim/env_params.hpp"

#include "common/core/config_error.hpp"

namespace masa::task {
namespace {

YAML::Node underEnv(const YAML::Node& env) {
  YAML::Node root(YAML::NodeType::Map);
  root["env"] = env;
  return root;
}

}  // namespace

EnvParams::EnvParams(YAML::Node env, std::map<std::string, std::string> origin, std::string default_origin)
    : env_(std::move(env)), reader_(underEnv(env_), std::move(origin), default_origin, "env") {
  if (env_.IsDefined() && !env_.IsNull() && !env_.IsMap())
    throw ConfigError(default_origin, "env", "expected a mapping of task parameters");
}

bool EnvParams::given(const std::string& key) {
  asked_.insert(key);
  const YAML::Node n = reader_.node(key);
  return n.IsDefined() && !n.IsNull();
}

double EnvParams::number(const std::string& key, double fallback) {
  return given(key) ? reader_.number(key) : fallback;
}

double EnvParams::positive(const std::string& key, double fallback) {
  const double v = number(key, fallback);
  if (!(v > 0)) reader_.fail(key, "must be positive, got " + config::formatNumber(v));
  return v;
}

int EnvParams::integer(const std::string& key, int fallback, int min_value) {
  if (given(key)) return reader_.atLeast(key, min_value);
  if (fallback < min_value)
    reader_.fail(key, "must be at least " + std::to_string(min_value) + ", got " + std::to_string(fallback));
  return fallback;
}

bool EnvParams::flag(const std::string& key, bool fallback) {
  return given(key) ? reader_.get<bool>(key, "true or false") : fallback;
}

std::string EnvParams::text(const std::string& key, const std::string& fallback) {
  if (!given(key)) return fallback;
  if (!reader_.node(key).IsScalar()) reader_.fail(key, "expected a string");
  return reader_.get<std::string>(key, "a string");
}

double EnvParams::weight(const std::string& term, double fallback) { return number("weights." + term, fallback); }

YAML::Node EnvParams::section(const std::string& key) {
  asked_.insert(key);
  return reader_.node(key);
}

void EnvParams::finish() const {
  // Walk every leaf key of env and check it was asked for.
  std::vector<std::pair<std::string, YAML::Node>> stack{{"", env_}};
  while (!stack.empty()) {
    auto [prefix, node] = stack.back();
    stack.pop_back();
    if (!node.IsMap()) continue;
    for (const auto& kv : node) {
      const std::string key = prefix.empty() ? kv.first.as<std::string>() : prefix + "." + kv.first.as<std::string>();
      if (asked_.count(key)) continue;  // a leaf, or a section its reader validated
      if (kv.second.IsMap()) {
        stack.emplace_back(key, kv.second);
      } else {
        std::string known;
        for (const auto& a : asked_) known += (known.empty() ? "" : ", ") + a;
        reader_.fail(key, "unknown task parameter (known: " + known + ")");
      }
    }
  }
}

}  // namespace masa::task
