// Typed, range-checked reads of one section of a resolved configuration tree: the one reader of
// run, offline, sac and deploy configs. Every error is a ConfigError naming the key path ("sac.tau")
// and the file (or "command line") that set it. Every number must be finite: YAML spells NaN and
// infinity (.nan, .inf) and no setting of ours means either, so a check like `v > 0` must not be
// the only thing between a typo and a poisoned run. Which keys exist, and their defaults, is the
// schema's business (config_layers.hpp: the defaults file is the schema).
#pragma once

#include <cmath>
#include <map>
#include <string>
#include <type_traits>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/core/config_error.hpp"

namespace masa::config {

using Origins = std::map<std::string, std::string>;  // key path -> file (or "command line") that set it

// `n` (at `path`, set in `file`) as a T; `what` says what was expected ("a number"). Floating-point
// values, alone or in a list, must be finite.
template <typename T>
T readValue(const YAML::Node& n, const std::string& file, const std::string& path, const std::string& what);

// "0.5", "1e+06": numbers in errors as a user would write them.
std::string formatNumber(double v);

// The one error of every config reader (run, task `env`, YAML task and spec files): the file, the
// key path and why, with the node's line where the file gave one.
[[noreturn]] void failAt(const std::string& file, const std::string& path, const YAML::Node& node, std::string what);

class ConfigSection {
 public:
  // `root` is the whole resolved tree, `prefix` this section's key path in it ("" for the root).
  // Keys no layer set come from `default_file`.
  ConfigSection(YAML::Node root, Origins origin, std::string default_file, std::string prefix = "");

  ConfigSection section(const std::string& key) const;
  std::string path(const std::string& key) const;  // the key's full path, for errors
  std::string originOf(const std::string& key) const;
  YAML::Node node(const std::string& key) const;

  template <typename T>
  T get(const std::string& key, const std::string& what) const {
    return readValue<T>(node(key), originOf(key), path(key), what);
  }
  double number(const std::string& key) const { return get<double>(key, "a number"); }
  double positive(const std::string& key) const;     // > 0
  double nonNegative(const std::string& key) const;  // >= 0
  // In [lo, hi], or with an open end where `open_lo` / `open_hi` say.
  double inRange(const std::string& key, double lo, double hi, bool open_lo = false, bool open_hi = false) const;
  // An integer of type I (int or long long, as `lo` is) of at least `lo`.
  template <typename I>
  I atLeast(const std::string& key, I lo) const {
    static_assert(std::is_integral_v<I>);
    const I v = get<I>(key, "an integer");
    if (v < lo) fail(key, "must be at least " + std::to_string(lo) + ", got " + std::to_string(v));
    return v;
  }
  int integerIn(const std::string& key, int lo, int hi) const;
  // Layer widths of a network: positive integers, at least one unless `allow_empty`.
  std::vector<int> widths(const std::string& key, bool allow_empty = false) const;
  // One of `choices`; the error lists them.
  std::string oneOf(const std::string& key, const std::vector<std::string>& choices) const;

  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  YAML::Node root_;
  Origins origin_;
  std::string default_file_, prefix_;
};

// ---- readValue's definition (a template: every caller's T)

namespace detail {
template <typename T>
struct IsFloatList : std::false_type {};
template <typename F>
struct IsFloatList<std::vector<F>> : std::is_floating_point<F> {};
}  // namespace detail

template <typename T>
T readValue(const YAML::Node& n, const std::string& file, const std::string& path, const std::string& what) {
  if (!n.IsDefined()) throw ConfigError(file, path, "missing: expected " + what);
  T v;
  try {
    v = n.as<T>();
  } catch (const YAML::Exception&) {
    failAt(file, path, n, "expected " + what + ", got '" + YAML::Dump(n) + "'");
  }
  bool finite = true;
  if constexpr (std::is_floating_point_v<T>) finite = std::isfinite(v);
  if constexpr (detail::IsFloatList<T>::value)
    for (const auto x : v) finite = finite && std::isfinite(x);
  if (!finite) failAt(file, path, n, "expected a finite number, got '" + YAML::Dump(n) + "'");
  return v;
}

}  // namespace masa::config
