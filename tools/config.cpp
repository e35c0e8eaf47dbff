// masa_config: print the resolved run configuration (defaults < task file < --set overrides).
//   masa_config --set task=a1_beam --set method=sasa --set ppo.horizon=8
//   masa_config --set @trifinger_lift_off_policy --rollout    (the rollout shape the learner reads)
//   masa_config --run-config runs/x/config.yaml --rollout      (a run directory's)
#include <CLI/CLI.hpp>
#include <iostream>

#include "common/config/run_config.hpp"
#include "common/core/build_info.hpp"
#include "common/core/config_error.hpp"
#include "common/symmetry/symmetry_spec.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Print the resolved masa run configuration"};
  app.set_version_flag("--version", masa::buildCommit());
  std::vector<std::string> overrides;
  std::string configs = masa::config::defaultConfigsDir();
  app.add_option("--set", overrides, "key.path=value override (repeatable), e.g. --set ppo.horizon=8");
  app.add_option("--configs", configs, "configs directory (defaults.yaml, tasks/, specs/)");
  std::string run_config;
  app.add_option("--run-config", run_config, "read this run directory's config.yaml instead of the task file")
      ->check(CLI::ExistingFile);
  bool rollout = false;
  app.add_flag("--rollout", rollout,
               "print only the rollout shape the learner reads (from ppo.* or, off-policy, sac.*), one key a line");
  CLI11_PARSE(app, argc, argv);
  try {
    const auto rc = masa::config::loadRunConfig(configs, overrides, run_config);
    masa::sym::SymmetrySpec::load(rc.spec_path);  // a run needs its spec: fail here, not later
    if (rollout) {
      // For the launchers (deploy/batch_size.sh): which section sizes the run, and its numbers.
      const auto& r = rc.rollout;
      std::cout << "section: " << r.section << "\nnum_envs: " << r.num_envs << "\nhorizon: " << r.horizon
                << "\nmax_updates: " << r.max_updates << "\nmax_policy_lag: " << r.max_policy_lag << "\n";
    } else {
      std::cout << masa::config::dumpResolved(rc);
    }
  } catch (const masa::ConfigError& e) {
    std::cerr << "masa_config: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
