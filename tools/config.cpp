// masa_config: print the resolved run configuration (defaults < task file < --set overrides).
//   masa_config --set task=a1_beam --set method=sasa --set ppo.horizon=8
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
  CLI11_PARSE(app, argc, argv);
  try {
    const auto rc = masa::config::loadRunConfig(configs, overrides);
    masa::sym::SymmetrySpec::load(rc.spec_path);  // a run needs its spec: fail here, not later
    std::cout << masa::config::dumpResolved(rc);
  } catch (const masa::ConfigError& e) {
    std::cerr << "masa_config: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
