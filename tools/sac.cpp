// masa_sac: off-policy SAC (learner/sac) on a task of the catalog, one environment in this process,
// as MASA, SA, SASA or MA; a progress line and a metrics.csv row every sac.log_every steps.
#include <CLI/CLI.hpp>
#include <omp.h>

#include <cstdio>
#include <iostream>

#include "common/core/build_info.hpp"
#include "common/core/config_error.hpp"
#include "learner/run_dir/run_directory.hpp"
#include "learner/sac/sac_run.hpp"

using namespace masa;

int main(int argc, char** argv) {
  CLI::App app{"masa sac: soft actor-critic with automatic temperature, single process"};
  app.set_version_flag("--version", masa::buildCommit());
  std::vector<std::string> overrides;
  std::string task = "a1_beam", method = "masa", run_dir, configs = config::defaultConfigsDir(), recipe, resume;
  long long steps = 0, seed = -1;
  int threads = 1;
  bool quiet = false;
  app.add_option("--task", task, "task of the catalog")->capture_default_str();
  app.add_option("--method", method, "masa | sa | sasa | ma")->capture_default_str();
  app.add_option("--steps", steps, "environment steps (default: sac.env_steps)")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "seed of everything random in the run (default: the config's)")->check(CLI::NonNegativeNumber);
  app.add_option("--resume", resume, "run directory to go on from (its config.yaml and sac_state.bin; --steps may raise the total)");
  app.add_option("--out", run_dir, "run directory (default runs/<task>_sac_<method>_<seed>_<time>)");
  app.add_option("--recipe", recipe, "a recipe of configs/recipes/ (or a YAML file) for the env section, before --set");
  app.add_option("--set", overrides, "key.path=value override (repeatable), e.g. --set sac.n_step=3");
  app.add_option("--configs", configs, "configs directory")->capture_default_str();
  app.add_option("--threads", threads, "OpenMP threads of the networks")->capture_default_str()->check(CLI::Range(1, 1024));
  app.add_flag("--quiet", quiet, "no progress lines");
  CLI11_PARSE(app, argc, argv);

  omp_set_num_threads(threads);
  try {
    if (!resume.empty()) {
      std::vector<std::string> all = overrides;
      if (steps > 0) all.push_back("sac.env_steps=" + std::to_string(steps));
      const config::RunConfig rc = config::loadRunConfig(configs, all, resume + "/config.yaml");
      sac::SacRunOptions o;
      o.run_dir = resume;
      o.verbose = !quiet;
      o.resume = true;
      sac::SacRun(rc, o).run();
      return 0;
    }
    std::vector<std::string> all = {"task=" + task};
    if (!recipe.empty()) all.push_back("@" + recipe);
    all.insert(all.end(), overrides.begin(), overrides.end());
    all.push_back("method=" + method);
    if (steps > 0) all.push_back("sac.env_steps=" + std::to_string(steps));
    if (seed >= 0) all.push_back("seed=" + std::to_string(seed));
    const config::RunConfig rc = config::loadRunConfig(configs, all);
    if (run_dir.empty()) run_dir = learner::defaultRunDir(rc.task + "_sac_" + method, rc.seed);
    sac::SacRunOptions o;
    o.run_dir = run_dir;
    o.verbose = !quiet;
    sac::SacRun(rc, o).run();
  } catch (const std::exception& e) {
    std::cerr << "masa_sac: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
