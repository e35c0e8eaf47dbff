// The configuration of a run: configs/defaults.yaml, overridden by configs/tasks/<task>.yaml,
// overridden by command-line `key.path=value` settings. defaults.yaml is also the schema: a key it
// does not have is an error (outside open sections such as env), and every error names the file
// (or "command line") and the key path. Read through config_layers.hpp and config_section.hpp, as
// every other config is.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/core/config_section.hpp"
#include "common/model/actor_critic.hpp"

namespace masa::config {

// PPO's numbers; its rollout shape (ppo.num_envs, ppo.horizon, ppo.max_updates, ppo.max_policy_lag)
// is read into RunConfig::rollout when PPO is the run's learner.
struct PpoConfig {
  int minibatch_size = 32768;
  int mini_epochs = 5;
  double learning_rate = 5e-4;
  std::string lr_schedule = "adaptive";  // adaptive | fixed
  double kl_threshold = 0.0008;
  double lr_min = 1e-6;
  double lr_max = 1e-2;
  double gamma = 0.99;
  double tau = 0.95;
  double e_clip = 0.2;
  double entropy_coef = 0.0;
  double critic_coef = 4.0;
  double bounds_loss_coef = 1e-4;
  double soft_bound = 1.1;
  double grad_norm = 1.0;
  bool normalize_value = true;
  bool normalize_advantage = true;
  bool value_bootstrap = true;
};

// How the actors' rollouts are shaped and how many a run takes, read from the section of the run's
// learner (ppo.* for PPO, sac.* for the off-policy learner), so that an algorithm is sized by its
// own numbers. Everything that collects rollouts (actors, learner intake, launchers) reads this.
struct RolloutShape {
  std::string section = "ppo";  // the section the numbers came from (for messages)
  int num_envs = 4096;          // environments per batch, over all actors
  int horizon = 32;             // steps per environment per batch
  int max_updates = 10000;      // batches (updates, or rounds of the off-policy learner) of a run
  int max_policy_lag = 0;       // policy versions an actor may act ahead of the learner
  // "<section>.<key>": the key path a message should name.
  std::string key(const std::string& name) const { return section + "." + name; }
};

// The learner's bookkeeping around the algorithm (rsl_rl's "runner").
struct RunnerConfig {
  int checkpoint_every = 10;       // updates between checkpoints (0: only on exit)
  double republish_every_s = 1.0;  // seconds between parameter re-broadcasts
  int plot_every = 10;             // updates between learning-curve renders (0: only on exit)
  int eval_every = 50;             // updates between evaluations of the policy mean (0: never)
  int eval_episodes = 8;           // episodes per evaluation
  double silence_warn_s = 30.0;    // seconds without rollout data before the learner says so (0: never)
  // Data-parallel ranks: a rank that hears no rollout data this long (its actors died or cannot
  // reach its URL) stops every rank, after a checkpoint, instead of leaving them waiting (0: never).
  double rank_silence_stop_s = 120.0;
  int snapshot_every = 0;          // updates between kept policies/policy_uNNNNNN.bin (0: none)
  // A batch short of lost environments forms once this share of rollout.num_envs arrived and the rest
  // is known lost (learner/intake/round_tracker.hpp); 1: batches are always full.
  double min_batch_fraction = 0.5;
  double loss_grace_s = 0.01;  // seconds after a rollout's latest chunk before its missing ones count as lost
  // Seconds after a parameter broadcast before it is repeated for a live actor that has not
  // acknowledged it (learner/params_delivery.hpp), then 1.5x longer each time up to
  // republish_every_s; 0: only the periodic republish.
  double repeat_unacknowledged_s = 0.05;
};

struct RunConfig {
  std::string task;
  model::Method method = model::Method::kMasa;
  std::uint64_t seed = 0;
  // ppo | off_policy: what masa_learner runs on the actors' rollouts (docs/off_policy.md).
  std::string learner = "ppo";
  std::string spec_path;  // resolved: absolute or relative to the configs dir's parent
  model::ModelConfig model;
  PpoConfig ppo;
  RolloutShape rollout;   // from the learner's own section
  RunnerConfig runner;
  YAML::Node env;         // task parameters, read by the task
  YAML::Node resolved;    // the whole merged tree, for the run directory
  std::map<std::string, std::string> origin;  // key path -> file (or "command line") that set it
  std::string defaults_file = "configs/defaults.yaml";  // the schema: where keys no layer set come from
};

// configs_dir holds defaults.yaml, tasks/ and specs/. overrides are "a.b=value" strings where value
// is YAML (1e-4, true, [256, 128], elu), or "@recipe": a YAML file overlaid after the task file
// (a path, or the name of one in configs/recipes/), checked like a task file; it may name the task.
// base_file, when given, is read instead of the task file: a run directory's config.yaml, so that a
// resumed run continues with exactly the configuration it started with (overrides still apply).
RunConfig loadRunConfig(const std::string& configs_dir, const std::vector<std::string>& overrides,
                        const std::string& base_file = "");

// The same from a resolved configuration held as text (a policy file's), named source_name in errors.
RunConfig loadRunConfigText(const std::string& configs_dir, const std::string& yaml_text,
                            const std::string& source_name, const std::vector<std::string>& overrides = {});
// The same with the middle layer given as a tree (empty: the task file), named base_file in errors.
RunConfig loadRunConfigOver(const std::string& configs_dir, const std::vector<std::string>& overrides,
                            const YAML::Node& base, const std::string& base_file);

// The typed, range-checked reader of one section of the resolved tree ("sac", "offline"), whose
// errors name the key path and the file that set it (config_section.hpp).
ConfigSection sectionOf(const RunConfig& config, const std::string& prefix);

// The configs directory of this source tree (MASA_SOURCE_DIR/configs) unless MASA_CONFIGS is set.
std::string defaultConfigsDir();

// YAML text of the resolved configuration, with a header comment naming its sources.
std::string dumpResolved(const RunConfig& config);

}  // namespace masa::config
