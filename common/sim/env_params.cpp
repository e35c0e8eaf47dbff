#include "common/sim/env_params.hpp"

#include <cmath>

#include <sstream>

#include "common/core/config_error.hpp"

namespace masa::task {

EnvParams::EnvParams(YAML::Node env, std::map<std::string, std::string> origin, std::string default_origin)
    : env_(std::move(env)), origin_(std::move(origin)), default_origin_(std::move(default_origin)) {
  if (env_.IsDefined() && !env_.IsNull() && !env_.IsMap())
    throw ConfigError(default_origin_, "env", "expected a mapping of task parameters");
}

YAML::Node EnvParams::lookup(const std::string& path) const {
  YAML::Node n;
  n.reset(env_);
  std::stringstream ss(path);
  std::string part;
  while (std::getline(ss, part, '.')) {
    if (!n.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
    YAML::Node next = n[part];
    if (!next.IsDefined()) return next;
    n.reset(next);
  }
  return n;
}

std::string EnvParams::originOf(const std::string& path) const {
  auto it = origin_.find("env." + path);
  if (it != origin_.end()) return it->second;
  // A whole sub-map (e.g. env.weights) may have been set at once.
  for (const auto& [k, v] : origin_)
    if (("env." + path).rfind(k + ".", 0) == 0) return v;
  return default_origin_;
}

double EnvParams::number(const std::string& key, double fallback) {
  asked_.insert(key);
  const YAML::Node n = lookup(key);
  if (!n.IsDefined() || n.IsNull()) return fallback;
  double v = 0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    throw ConfigError(originOf(key), "env." + key, "expected a number, got '" + YAML::Dump(n) + "'");
  }
  // YAML spells NaN and infinity (.nan, .inf): a reward weight or a gain of either poisons a run.
  if (!std::isfinite(v)) throw ConfigError(originOf(key), "env." + key, "expected a finite number, got '" + YAML::Dump(n) + "'");
  return v;
}

double EnvParams::positive(const std::string& key, double fallback) {
  const double v = number(key, fallback);
  if (!(v > 0)) throw ConfigError(originOf(key), "env." + key, "must be positive, got " + std::to_string(v));
  return v;
}

int EnvParams::integer(const std::string& key, int fallback, int min_value) {
  asked_.insert(key);
  const YAML::Node n = lookup(key);
  int v = fallback;
  if (n.IsDefined() && !n.IsNull()) {
    try {
      v = n.as<int>();
    } catch (const YAML::Exception&) {
      throw ConfigError(originOf(key), "env." + key, "expected an integer, got '" + YAML::Dump(n) + "'");
    }
  }
  if (v < min_value)
    throw ConfigError(originOf(key), "env." + key, "must be at least " + std::to_string(min_value) + ", got " + std::to_string(v));
  return v;
}

bool EnvParams::flag(const std::string& key, bool fallback) {
  asked_.insert(key);
  const YAML::Node n = lookup(key);
  if (!n.IsDefined() || n.IsNull()) return fallback;
  try {
    return n.as<bool>();
  } catch (const YAML::Exception&) {
    throw ConfigError(originOf(key), "env." + key, "expected true or false, got '" + YAML::Dump(n) + "'");
  }
}

std::string EnvParams::text(const std::string& key, const std::string& fallback) {
  asked_.insert(key);
  const YAML::Node n = lookup(key);
  if (!n.IsDefined() || n.IsNull()) return fallback;
  if (!n.IsScalar()) throw ConfigError(originOf(key), "env." + key, "expected a string");
  return n.Scalar();
}

double EnvParams::weight(const std::string& term, double fallback) { return number("weights." + term, fallback); }

YAML::Node EnvParams::section(const std::string& key) {
  asked_.insert(key);
  return lookup(key);
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
        throw ConfigError(originOf(key), "env." + key, "unknown task parameter (known: " + known + ")");
      }
    }
  }
}

}  // namespace masa::task
