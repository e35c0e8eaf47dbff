#include "common/config/run_config.hpp"

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "common/config/config_layers.hpp"
#include "common/core/build_info.hpp"
#include "common/core/config_error.hpp"
#include "common/core/env_directory.hpp"

namespace masa::config {
namespace fs = std::filesystem;
namespace {

// Keys renamed since runs were first recorded, read under their new name so that old run
// directories, policy files and configs still load: (old full path, new key in the same section).
// ppo.max_epochs became ppo.max_updates when the update got one name (issue #32).
const SchemaRules kRunRules{{"env"}, {{"ppo.max_epochs", "max_updates"}}};

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

// The keys that shape the rollouts, as PPO names them and as the off-policy learner does.
struct ShapeKey {
  const char* ppo;
  const char* off_policy;
};
constexpr ShapeKey kShapeKeys[] = {
    {"num_envs", "num_envs"}, {"horizon", "horizon"}, {"max_policy_lag", "max_policy_lag"}, {"max_updates", "env_steps"}};

RolloutShape readPpoShape(const ConfigSection& r) {
  RolloutShape s;
  s.section = "ppo";
  s.num_envs = r.atLeast("ppo.num_envs", 1);
  s.horizon = r.atLeast("ppo.horizon", 1);
  s.max_updates = r.atLeast("ppo.max_updates", 1);
  s.max_policy_lag = r.atLeast("ppo.max_policy_lag", 0);
  return s;
}

// Run directories and policy files written before the off-policy learner had its own sizing keys
// sized it with ppo.*. Where such a file (the base layer) holds ppo.num_envs and no sac.num_envs,
// those numbers move to the sac section as they were meant (ppo.max_updates rounds become
// sac.env_steps), so the run reads, and its config.yaml is written, as a new one would be. A
// recipe or command line that sizes an off-policy run with ppo.* is refused instead
// (readOffPolicyShape), since nothing wrote it before the change.
void migrateOffPolicyShape(YAML::Node tree, Origins& origin, const YAML::Node& schema, const std::string& base_file,
                           const std::string& defaults_file) {
  const auto from_base = [&](const std::string& key) { return origin.count(key) && origin.at(key) == base_file; };
  if (!from_base("ppo.num_envs") || origin.count("sac.num_envs")) return;
  const ConfigSection r(tree, origin, defaults_file);
  const RolloutShape old = readPpoShape(r);
  const std::string from = origin.at("ppo.num_envs");
  YAML::Node sac = tree["sac"], ppo = tree["ppo"];
  sac["num_envs"] = old.num_envs;
  sac["horizon"] = old.horizon;
  sac["max_policy_lag"] = old.max_policy_lag;
  sac["env_steps"] = static_cast<long long>(old.max_updates) * old.num_envs * old.horizon;
  for (const ShapeKey& k : kShapeKeys) {
    ppo[k.ppo] = YAML::Clone(schema["ppo"][k.ppo]);
    origin.erase(std::string("ppo.") + k.ppo);
    origin["sac." + std::string(k.off_policy)] = from;
  }
}

// The off-policy learner is sized by its own section: sac.num_envs x sac.horizon transitions a
// round, sac.env_steps of them in all. A task file's ppo.* sizes the task's PPO runs and is not
// read here; a recipe or command line that sets a PPO sizing key for an off-policy run asks for
// something that would be silently ignored, so it is refused.
RolloutShape readOffPolicyShape(const ConfigSection& r, const std::string& defaults_file, const std::string& task_file) {
  for (const ShapeKey& k : kShapeKeys) {
    const std::string ppo_key = std::string("ppo.") + k.ppo;
    const std::string from = r.originOf(ppo_key);
    if (from == defaults_file || from == task_file) continue;
    r.fail(ppo_key, std::string("is PPO's: learner off_policy is sized by sac.") + k.off_policy +
                        " (set that instead, or learner: ppo)");
  }
  RolloutShape s;
  s.section = "sac";
  s.num_envs = r.atLeast("sac.num_envs", 1);
  s.horizon = r.atLeast("sac.horizon", 1);
  s.max_policy_lag = r.atLeast("sac.max_policy_lag", 0);
  const long long env_steps = r.atLeast("sac.env_steps", 1LL);
  const long long round = static_cast<long long>(s.num_envs) * s.horizon;
  const long long rounds = (env_steps + round - 1) / round;
  if (rounds > 1000000000LL) r.fail("sac.env_steps", "is more than 1e9 rounds of sac.num_envs x sac.horizon");
  s.max_updates = static_cast<int>(rounds);
  return s;
}

}  // namespace

ConfigSection sectionOf(const RunConfig& config, const std::string& prefix) {
  return ConfigSection(config.resolved, config.origin, config.defaults_file, prefix);
}

std::string defaultConfigsDir() {
  return directoryFromEnvironment("MASA_CONFIGS", std::string(MASA_SOURCE_DIR) + "/configs");
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
  // Read below before any layer: a damaged schema is named here, not by yaml-cpp's InvalidNode.
  if (!schema.IsMap() || !schema["task"])
    throw ConfigError(defaults_file, "task", "the schema has no task key (is the file damaged or cut short?)");
  RunConfig rc;
  rc.defaults_file = defaults_file;
  ConfigLayers layers(schema, defaults_file, kRunRules);

  // Parse overrides first: the task they name decides which task file is read.
  std::vector<std::pair<std::string, YAML::Node>> parsed;
  std::vector<std::pair<std::string, YAML::Node>> recipe_files;  // "@file.yaml" overrides: (file, tree)
  // A run's own config.yaml (resume) replaces the task file as the middle layer: it already holds
  // the task file's values as they were when the run started.
  const bool has_base = base.IsMap();
  // The task names the file read next, so its errors name the layer that set it (a recipe, the
  // command line), not the task file that is not there.
  auto taskName = [](const YAML::Node& n, const std::string& file) {
    if (!n.IsScalar()) throw ConfigError(file, "task", "expected a task name");
    return n.as<std::string>();
  };
  std::string task_origin = has_base && base["task"] ? base_file : defaults_file;
  std::string task = taskName(has_base && base["task"] ? base["task"] : schema["task"], task_origin);
  for (const std::string& o : overrides) {
    if (!o.empty() && o[0] == '@') {  // a recipe: a whole YAML overlay, checked like a task file
      const std::string file = resolveRecipe(configs_dir, o.substr(1));
      const YAML::Node node = loadYamlFile(file, "(file)");
      if (node.IsMap() && node["task"]) task = taskName(node["task"], task_origin = file);
      recipe_files.emplace_back(file, node);
      continue;
    }
    parsed.push_back(parseSetting(o));
    if (parsed.back().first == "task") task = taskName(parsed.back().second, task_origin = "command line");
  }

  const std::string task_file = has_base ? base_file : configs_dir + "/tasks/" + task + ".yaml";
  const bool plain_name = !task.empty() && task.find('/') == std::string::npos && task != "." && task != "..";
  if (!has_base && (!plain_name || !fs::exists(task_file))) {
    std::string known;
    if (fs::exists(configs_dir + "/tasks"))
      for (const auto& e : fs::directory_iterator(configs_dir + "/tasks"))
        if (e.path().extension() == ".yaml") known += (known.empty() ? "" : ", ") + e.path().stem().string();
    throw ConfigError(task_origin, "task",
                      "unknown task '" + task + "' (no file " + task_file + "; known: " + known + ")");
  }
  layers.overlay(has_base ? base : loadYamlFile(task_file, "task"), task_file);
  for (const auto& [file, node] : recipe_files) layers.overlay(node, file);
  for (const auto& [path, value] : parsed) layers.set(path, value);
  rc.origin = layers.origin();
  const YAML::Node merged = YAML::Clone(layers.tree());
  {
    const ConfigSection top(merged, rc.origin, defaults_file);
    if (has_base && top.oneOf("learner", {"ppo", "off_policy"}) == "off_policy")
      migrateOffPolicyShape(merged, rc.origin, schema, base_file, defaults_file);
  }

  const ConfigSection r(merged, rc.origin, defaults_file);
  rc.task = r.get<std::string>("task", "a task name");
  rc.learner = r.oneOf("learner", {"ppo", "off_policy"});
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
  p.minibatch_size = r.atLeast("ppo.minibatch_size", 1);
  p.mini_epochs = r.atLeast("ppo.mini_epochs", 1);
  p.learning_rate = r.positive("ppo.learning_rate");
  p.lr_schedule = r.oneOf("ppo.lr_schedule", {"adaptive", "fixed"});
  p.kl_threshold = r.positive("ppo.kl_threshold");
  p.lr_min = r.positive("ppo.lr_min");
  p.lr_max = r.positive("ppo.lr_max");
  if (p.lr_min > p.lr_max) throw ConfigError(r.originOf("ppo.lr_min"), "ppo.lr_min", "must not exceed ppo.lr_max");
  p.gamma = r.inRange("ppo.gamma", 0.0, 1.0, true);
  p.tau = r.inRange("ppo.tau", 0.0, 1.0, true);
  p.e_clip = r.positive("ppo.e_clip");
  p.entropy_coef = r.nonNegative("ppo.entropy_coef");
  p.critic_coef = r.nonNegative("ppo.critic_coef");
  p.bounds_loss_coef = r.nonNegative("ppo.bounds_loss_coef");
  p.soft_bound = r.positive("ppo.soft_bound");
  p.grad_norm = r.positive("ppo.grad_norm");
  p.normalize_value = r.get<bool>("ppo.normalize_value", "true or false");
  p.normalize_advantage = r.get<bool>("ppo.normalize_advantage", "true or false");
  p.value_bootstrap = r.get<bool>("ppo.value_bootstrap", "true or false");
  rc.rollout = rc.learner == "off_policy" ? readOffPolicyShape(r, defaults_file, task_file) : readPpoShape(r);

  RunnerConfig& u = rc.runner;
  u.checkpoint_every = r.atLeast("runner.checkpoint_every", 0);
  u.republish_every_s = r.positive("runner.republish_every_s");
  u.plot_every = r.atLeast("runner.plot_every", 0);
  u.eval_every = r.atLeast("runner.eval_every", 0);
  u.eval_episodes = r.atLeast("runner.eval_episodes", 1);
  u.silence_warn_s = r.nonNegative("runner.silence_warn_s");
  u.rank_silence_stop_s = r.nonNegative("runner.rank_silence_stop_s");
  u.snapshot_every = r.atLeast("runner.snapshot_every", 0);
  u.min_batch_fraction = r.inRange("runner.min_batch_fraction", 0.0, 1.0, true);
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
