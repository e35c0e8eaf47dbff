// masa_offline: behaviour cloning or implicit Q-learning on recorded datasets (LCM logs), as SA,
// SASA-data (SA on the dataset augmented with its symmetric images) or MASA.
//   masa_offline --dataset data/a1_expert.lcm --algo iql --method masa --steps 100000 --out runs/a1_iql_masa
//   masa_offline --dataset a.lcm b.lcm --algo bc --method sasa-data --seed 3 --set offline.bc_loss=mse
// The task is the dataset's; its env section (reward weights, episode length) is the task file's
// unless --env-of names the policy that recorded the data (evaluate where it was recorded) or
// --recipe the recipe it was trained with. Networks default to IQL's (256, 256) for policy, V and Q (--set
// model.policy_hidden=[...] to change); every other number is configs/defaults.yaml's `offline`
// section. The run directory gets config.yaml, metrics.csv, learning_curve.png, policy.bin (for
// masa_eval --policy and the robot runner) and eval.txt (the final evaluation, 100 episodes).
#include <CLI/CLI.hpp>
#include <omp.h>

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "common/core/build_info.hpp"
#include "common/core/config_error.hpp"
#include "common/dataset/dataset_log.hpp"
#include "common/policy/policy_file.hpp"
#include "learner/offline/offline_run.hpp"

using namespace masa;

namespace {

// The paper's offline methods as run settings: SASA-data is the SA model on augmented data.
std::vector<std::string> methodSettings(const std::string& method) {
  if (method == "sa") return {"method=sa", "offline.augment=false"};
  if (method == "sasa-data") return {"method=sa", "offline.augment=true"};
  if (method == "masa") return {"method=masa", "offline.augment=false"};
  throw std::runtime_error("unknown method '" + method + "' (offline methods: sa, sasa-data, masa)");
}

// "env=<the policy file's env section>" as one override (YAML flow style on one line).
std::string envOf(const std::string& target) {
  namespace fs = std::filesystem;
  fs::path p = target;
  if (fs::is_directory(p)) p /= "policy.bin";
  const policy::LoadedPolicy lp = policy::loadPolicyFile(p.string());
  YAML::Emitter out;
  out.SetMapFormat(YAML::Flow);
  out.SetSeqFormat(YAML::Flow);
  out << lp.config.env;
  return std::string("env=") + out.c_str();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"masa offline: BC or IQL on recorded datasets, as SA, SASA-data or MASA"};
  app.set_version_flag("--version", masa::buildCommit());
  std::vector<std::string> logs, overrides;
  std::string algo = "iql", method = "masa", run_dir, configs = config::defaultConfigsDir(), recipe, env_of;
  long long steps = 0;
  long long seed = -1;
  int threads = 1;
  bool quiet = false;
  app.add_option("--dataset", logs, "LCM log(s) of the dataset (recorded by masa_dataset)")->required();
  app.add_option("--algo", algo, "bc | iql")->capture_default_str();
  app.add_option("--method", method, "sa | sasa-data | masa")->capture_default_str();
  app.add_option("--steps", steps, "gradient steps (default: offline.steps)")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "seed of initialization and sampling (default: the config's)")->check(CLI::NonNegativeNumber);
  app.add_option("--out", run_dir, "run directory (default runs/<task>_offline_<algo>_<method>_<seed>)");
  app.add_option("--env-of", env_of, "policy file or run directory whose env section to use (the recording policy's)");
  app.add_option("--recipe", recipe, "a recipe of configs/recipes/ (or a YAML file), applied before --set");
  app.add_option("--set", overrides, "key.path=value override (repeatable), e.g. --set offline.beta=10");
  app.add_option("--configs", configs, "configs directory")->capture_default_str();
  app.add_option("--threads", threads, "OpenMP threads of the networks and of the evaluation episodes")->capture_default_str()
      ->check(CLI::Range(1, 1024));
  app.add_flag("--quiet", quiet, "no progress lines");
  CLI11_PARSE(app, argc, argv);

  // One thread by default: at batch 256 the networks gain little from a second, and on a shared
  // machine OpenMP's barriers can wait on a busy core far longer than the work takes.
  omp_set_num_threads(threads);
  try {
    if (algo != "bc" && algo != "iql") throw std::runtime_error("unknown algorithm '" + algo + "' (bc, iql)");
    std::vector<std::string> settings = methodSettings(method);
    dataset::LogReadReport report;
    dataset::TransitionDataset data = dataset::readDatasetLogs(logs, &report);
    if (!quiet) std::printf("%s", report.summary().c_str());
    if (data.task.empty()) throw std::runtime_error("the dataset names no task: cannot tell which simulator to evaluate in");
    // Defaults < offline network sizes < the dataset's task < recipe < recording env < --set < flags.
    std::vector<std::string> all = {"model.policy_hidden=[256, 256]", "model.critic_hidden=[256, 256]",
                                    "task=" + data.task};
    if (!recipe.empty()) all.push_back("@" + recipe);
    if (!env_of.empty()) all.push_back(envOf(env_of));
    all.insert(all.end(), overrides.begin(), overrides.end());
    all.insert(all.end(), settings.begin(), settings.end());
    all.push_back("offline.algo=" + algo);
    if (steps > 0) all.push_back("offline.steps=" + std::to_string(steps));
    if (seed >= 0) all.push_back("seed=" + std::to_string(seed));
    const config::RunConfig rc = config::loadRunConfig(configs, all);
    if (run_dir.empty())
      run_dir = "runs/" + rc.task + "_offline_" + algo + "_" + method + "_" + std::to_string(rc.seed);
    offline::OfflineRunOptions o;
    o.run_dir = run_dir;
    o.verbose = !quiet;
    o.eval_threads = threads;
    offline::OfflineRun(rc, std::move(data), o).run();
  } catch (const ConfigError& e) {
    std::cerr << "masa_offline: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "masa_offline: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
