#include "common/config/run_config.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <type_traits>

#include "common/core/build_info.hpp"
#include "common/core/config_error.hpp"

namespace masa::config {
namespace fs = std::filesystem;
namespace {

const char* kCommandLine = "command line";

bool isOpenSection(const std::string& path) { return path == "env" || path.rfind("env.", 0) == 0; }

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

YAML::Node loadYamlFile(const std::string& path, const std::string& key_for_missing) {
  if (!fs::exists(path)) throw ConfigError(path, key_for_missing, "file not found");
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw ConfigError(path, "(syntax)", "YAML error at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
}

// Deep merge without a schema (open sections): maps merge key by key, anything else replaces.
void mergeOpen(YAML::Node dst, const YAML::Node& src, const std::string& path, const std::string& file,
               std::map<std::string, std::string>& origin) {
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

// Keys renamed since runs were first recorded, read under their new name so that old run
// directories, policy files and configs still load: (old full path, new key in the same section).
// ppo.max_epochs became ppo.max_updates when the update got one name (issue #32).
const std::map<std::string, std::string> kRenamedKeys = {{"ppo.max_epochs", "max_updates"}};

// Overlays `src` onto `dst` (a clone of the schema tree), checking every key against `schema`.
void overlay(YAML::Node dst, const YAML::Node& src, const YAML::Node& schema, const std::string& path,
             const std::string& file, std::map<std::string, std::string>& origin) {
  if (!src.IsMap()) throw ConfigError(file, path.empty() ? "(root)" : path, "expected a map, got " + kindName(src));
  for (const auto& kv : src) {
    std::string key = kv.first.as<std::string>();
    if (const auto renamed = kRenamedKeys.find(join(path, key)); renamed != kRenamedKeys.end()) key = renamed->second;
    const std::string full = join(path, key);
    const YAML::Node value = kv.second;
    if (isOpenSection(full)) {
      if (value.IsMap() && dst[key].IsMap()) {
        mergeOpen(dst[key], value, full, file, origin);
      } else {
        dst[key] = YAML::Clone(value);
        origin[full] = file;
      }
      continue;
    }
    const YAML::Node expected = schema[key];
    if (!expected) {
      std::string known;
      for (const auto& s : schema) known += (known.empty() ? "" : ", ") + s.first.as<std::string>();
      throw ConfigError(file, full, "unknown key (known here: " + known + ")");
    }
    if (expected.IsMap()) {
      overlay(dst[key], value, expected, full, file, origin);
    } else {
      if (expected.IsSequence() && !value.IsSequence())
        throw ConfigError(file, full, "expected a list, got " + kindName(value));
      if (expected.IsScalar() && !value.IsScalar())
        throw ConfigError(file, full, "expected a value, got " + kindName(value));
      dst[key] = YAML::Clone(value);
      origin[full] = file;
    }
  }
}

// Typed readers that name the origin of the key on failure.
class Reader {
 public:
  Reader(const YAML::Node& root, const std::map<std::string, std::string>& origin, std::string defaults_file)
      : root_(root), origin_(origin), defaults_(std::move(defaults_file)) {}

  YAML::Node node(const std::string& path) const {
    YAML::Node n;
    n.reset(root_);  // reset() rebinds; operator= would overwrite the node's contents
    std::stringstream ss(path);
    std::string part;
    while (std::getline(ss, part, '.')) n.reset(n[part]);
    return n;
  }
  std::string originOf(const std::string& path) const {
    auto it = origin_.find(path);
    return it == origin_.end() ? defaults_ : it->second;
  }
  template <typename T>
  T get(const std::string& path, const char* what) const {
    const YAML::Node n = node(path);
    T v;
    try {
      v = n.as<T>();
    } catch (const YAML::Exception&) {
      throw ConfigError(originOf(path), path, std::string("expected ") + what + ", got '" + YAML::Dump(n) + "'");
    }
    // YAML spells NaN and infinity (.nan, .inf); no setting of a run means either.
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(v)) throw ConfigError(originOf(path), path, "expected a finite number, got '" + YAML::Dump(n) + "'");
    }
    return v;
  }
  double positive(const std::string& path) const {
    const double v = get<double>(path, "a number");
    if (!(v > 0)) throw ConfigError(originOf(path), path, "must be positive, got " + std::to_string(v));
    return v;
  }
  double nonNegative(const std::string& path) const {
    const double v = get<double>(path, "a number");
    if (!(v >= 0)) throw ConfigError(originOf(path), path, "must not be negative, got " + std::to_string(v));
    return v;
  }
  double unitInterval(const std::string& path) const {
    const double v = get<double>(path, "a number");
    if (!(v > 0 && v <= 1)) throw ConfigError(originOf(path), path, "must be in (0, 1], got " + std::to_string(v));
    return v;
  }
  int atLeast(const std::string& path, int lo) const {
    const int v = get<int>(path, "an integer");
    if (v < lo) throw ConfigError(originOf(path), path, "must be at least " + std::to_string(lo) + ", got " + std::to_string(v));
    return v;
  }
  std::vector<int> widths(const std::string& path, bool allow_empty) const {
    const auto v = get<std::vector<int>>(path, "a list of integers");
    if (v.empty() && !allow_empty) throw ConfigError(originOf(path), path, "needs at least one layer width");
    for (int w : v)
      if (w < 1) throw ConfigError(originOf(path), path, "layer widths must be positive, got " + std::to_string(w));
    return v;
  }

 private:
  const YAML::Node& root_;
  const std::map<std::string, std::string>& origin_;
  std::string defaults_;
};

// "@x" names a recipe: a file path as given, or configs/recipes/x.yaml.
std::string resolveRecipe(const std::string& configs_dir, const std::string& name) {
  if (name.empty()) throw ConfigError(kCommandLine, "@", "expected @<recipe name or file>");
  if (fs::exists(name) && !fs::is_directory(name)) return name;
  const std::string in_configs = configs_dir + "/recipes/" + name + ".yaml";
  if (fs::exists(in_configs)) return in_configs;
  std::string known;
  if (fs::exists(configs_dir + "/recipes"))
    for (const auto& e : fs::directory_iterator(configs_dir + "/recipes"))
      if (e.path().extension() == ".yaml") known += (known.empty() ? "" : ", ") + e.path().stem().string();
  throw ConfigError(kCommandLine, "@" + name, "no recipe file '" + name + "' nor " + in_configs + " (recipes: " + known + ")");
}

}  // namespace

void overlayChecked(YAML::Node dst, const YAML::Node& src, const YAML::Node& schema, const std::string& file,
                    std::map<std::string, std::string>& origin) {
  overlay(dst, src, schema, "", file, origin);
}

std::string defaultConfigsDir() {
  if (const char* env = std::getenv("MASA_CONFIGS")) return env;
  return std::string(MASA_SOURCE_DIR) + "/configs";
}

RunConfig loadRunConfig(const std::string& configs_dir, const std::vector<std::string>& overrides,
                        const std::string& base_file) {
  YAML::Node base;
  if (!base_file.empty()) base = loadYamlFile(base_file, "(file)");
  return loadRunConfigOver(configs_dir, overrides, base, base_file);
}

RunConfig loadRunConfigText(const std::string& configs_dir, const std::string& yaml_text,
                            const std::string& source_name, const std::vector<std::string>& overrides) {
  YAML::Node base;
  try {
    base = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(source_name, "(syntax)", "YAML error at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!base.IsMap()) throw ConfigError(source_name, "(root)", "expected a map of settings");
  return loadRunConfigOver(configs_dir, overrides, base, source_name);
}

RunConfig loadRunConfigOver(const std::string& configs_dir, const std::vector<std::string>& overrides,
                            const YAML::Node& base, const std::string& base_file) {
  const std::string defaults_file = configs_dir + "/defaults.yaml";
  const YAML::Node schema = loadYamlFile(defaults_file, "(file)");
  RunConfig rc;
  YAML::Node merged = YAML::Clone(schema);

  // Parse overrides first: the task they name decides which task file is read.
  std::vector<std::pair<std::string, YAML::Node>> parsed;
  std::vector<std::pair<std::string, YAML::Node>> recipe_files;  // "@file.yaml" overrides: (file, tree)
  // A run's own config.yaml (resume) replaces the task file as the middle layer: it already holds
  // the task file's values as they were when the run started.
  const bool has_base = base.IsMap();
  std::string task = has_base && base["task"] ? base["task"].as<std::string>() : schema["task"].as<std::string>();
  for (const std::string& o : overrides) {
    if (!o.empty() && o[0] == '@') {  // a recipe: a whole YAML overlay, checked like a task file
      const std::string file = resolveRecipe(configs_dir, o.substr(1));
      const YAML::Node node = loadYamlFile(file, "(file)");
      if (node.IsMap() && node["task"]) task = node["task"].as<std::string>();
      recipe_files.emplace_back(file, node);
      continue;
    }
    const auto eq = o.find('=');
    if (eq == std::string::npos || eq == 0)
      throw ConfigError(kCommandLine, o, "expected key.path=value");
    const std::string path = o.substr(0, eq);
    YAML::Node value;
    try {
      value = YAML::Load(o.substr(eq + 1));
    } catch (const YAML::Exception& e) {
      throw ConfigError(kCommandLine, path, "value is not valid YAML: " + e.msg);
    }
    if (path == "task") task = value.as<std::string>();
    parsed.emplace_back(path, value);
  }

  const std::string task_file = has_base ? base_file : configs_dir + "/tasks/" + task + ".yaml";
  if (!has_base && !fs::exists(task_file)) {
    std::string known;
    if (fs::exists(configs_dir + "/tasks"))
      for (const auto& e : fs::directory_iterator(configs_dir + "/tasks"))
        if (e.path().extension() == ".yaml") known += (known.empty() ? "" : ", ") + e.path().stem().string();
    throw ConfigError(task_file, "task", "unknown task '" + task + "' (known: " + known + ")");
  }
  const YAML::Node task_node = has_base ? base : loadYamlFile(task_file, "task");
  if (task_node.IsDefined() && !task_node.IsNull()) overlay(merged, task_node, schema, "", task_file, rc.origin);

  for (const auto& [file, node] : recipe_files)
    if (node.IsDefined() && !node.IsNull()) overlay(merged, node, schema, "", file, rc.origin);

  for (const auto& [path, value] : parsed) {
    // Build {a: {b: value}} and overlay it, so overrides get exactly the file checks.
    YAML::Node wrapped;
    wrapped.reset(value);
    std::vector<std::string> parts;
    std::stringstream ss(path);
    std::string part;
    while (std::getline(ss, part, '.')) parts.push_back(part);
    for (auto it = parts.rbegin(); it != parts.rend(); ++it) {
      YAML::Node m(YAML::NodeType::Map);
      m[*it] = wrapped;
      wrapped.reset(m);
    }
    overlay(merged, wrapped, schema, "", kCommandLine, rc.origin);
  }

  const Reader r(merged, rc.origin, defaults_file);
  rc.task = r.get<std::string>("task", "a task name");
  try {
    rc.method = model::parseMethod(r.get<std::string>("method", "a method name"));
  } catch (const std::invalid_argument& e) {
    throw ConfigError(r.originOf("method"), "method", e.what());
  }
  rc.seed = r.get<std::uint64_t>("seed", "a non-negative integer");
  rc.spec_path = r.get<std::string>("spec", "a file path");
  if (rc.spec_path.empty()) {
    rc.spec_path = configs_dir + "/specs/" + rc.task + ".yaml";
  } else if (const fs::path in_tree = fs::path(configs_dir).parent_path() / rc.spec_path;
             fs::path(rc.spec_path).is_relative() && fs::exists(in_tree)) {
    rc.spec_path = in_tree.string();  // a task file's spec: relative to the source tree, wherever the run starts
  }

  model::ModelConfig& m = rc.model;
  m.method = rc.method;
  m.policy_hidden = r.widths("model.policy_hidden", false);
  m.critic_hidden = r.widths("model.critic_hidden", false);
  m.critic_head_hidden = r.widths("model.critic_head_hidden", true);
  try {
    m.activation = nn::parseActivation(r.get<std::string>("model.activation", "an activation name"));
  } catch (const std::invalid_argument& e) {
    throw ConfigError(r.originOf("model.activation"), "model.activation", e.what());
  }
  m.init_log_std = r.get<double>("model.init_log_std", "a number");
  m.policy_last_layer_scale = r.positive("model.policy_last_layer_scale");
  m.normalize_obs = r.get<bool>("model.normalize_input", "true or false");
  m.sasa_policy_coef = r.nonNegative("model.sasa_policy_coef");
  m.sasa_value_coef = r.nonNegative("model.sasa_value_coef");

  PpoConfig& p = rc.ppo;
  p.num_envs = r.atLeast("ppo.num_envs", 1);
  p.horizon = r.atLeast("ppo.horizon", 1);
  p.minibatch_size = r.atLeast("ppo.minibatch_size", 1);
  p.mini_epochs = r.atLeast("ppo.mini_epochs", 1);
  p.learning_rate = r.positive("ppo.learning_rate");
  p.lr_schedule = r.get<std::string>("ppo.lr_schedule", "adaptive or fixed");
  if (p.lr_schedule != "adaptive" && p.lr_schedule != "fixed")
    throw ConfigError(r.originOf("ppo.lr_schedule"), "ppo.lr_schedule",
                      "expected 'adaptive' or 'fixed', got '" + p.lr_schedule + "'");
  p.kl_threshold = r.positive("ppo.kl_threshold");
  p.lr_min = r.positive("ppo.lr_min");
  p.lr_max = r.positive("ppo.lr_max");
  if (p.lr_min > p.lr_max) throw ConfigError(r.originOf("ppo.lr_min"), "ppo.lr_min", "must not exceed ppo.lr_max");
  p.gamma = r.unitInterval("ppo.gamma");
  p.tau = r.unitInterval("ppo.tau");
  p.e_clip = r.positive("ppo.e_clip");
  p.entropy_coef = r.nonNegative("ppo.entropy_coef");
  p.critic_coef = r.nonNegative("ppo.critic_coef");
  p.bounds_loss_coef = r.nonNegative("ppo.bounds_loss_coef");
  p.soft_bound = r.positive("ppo.soft_bound");
  p.grad_norm = r.positive("ppo.grad_norm");
  p.normalize_value = r.get<bool>("ppo.normalize_value", "true or false");
  p.normalize_advantage = r.get<bool>("ppo.normalize_advantage", "true or false");
  p.value_bootstrap = r.get<bool>("ppo.value_bootstrap", "true or false");
  p.max_updates = r.atLeast("ppo.max_updates", 1);
  p.max_policy_lag = r.atLeast("ppo.max_policy_lag", 0);

  RunnerConfig& u = rc.runner;
  u.checkpoint_every = r.atLeast("runner.checkpoint_every", 0);
  u.republish_every_s = r.positive("runner.republish_every_s");
  u.plot_every = r.atLeast("runner.plot_every", 0);
  u.eval_every = r.atLeast("runner.eval_every", 0);
  u.eval_episodes = r.atLeast("runner.eval_episodes", 1);
  u.silence_warn_s = r.nonNegative("runner.silence_warn_s");
  u.rank_silence_stop_s = r.nonNegative("runner.rank_silence_stop_s");
  u.snapshot_every = r.atLeast("runner.snapshot_every", 0);
  u.min_batch_fraction = r.positive("runner.min_batch_fraction");
  if (u.min_batch_fraction > 1.0)
    throw ConfigError(r.originOf("runner.min_batch_fraction"), "runner.min_batch_fraction",
                      "must be in (0, 1], got " + std::to_string(u.min_batch_fraction));
  u.loss_grace_s = r.positive("runner.loss_grace_s");
  u.repeat_unacknowledged_s = r.nonNegative("runner.repeat_unacknowledged_s");

  rc.env = YAML::Clone(merged["env"]);
  rc.resolved = merged;
  return rc;
}

std::string dumpResolved(const RunConfig& config) {
  std::ostringstream os;
  os << "# Resolved masa run configuration (defaults < task file < command line).\n";
  os << "# Written by masa " << buildCommit() << "\n";
  std::map<std::string, int> files;
  for (const auto& [key, file] : config.origin) files[file]++;
  for (const auto& [file, n] : files) os << "# " << n << " key(s) from " << file << "\n";
  YAML::Emitter out;
  out << config.resolved;
  os << out.c_str() << "\n";
  return os.str();
}

}  // namespace masa::config
