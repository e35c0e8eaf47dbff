// masa_verify: prove a symmetry spec against the physics.
//   masa_verify --task a1_beam                       a shipped task, its spec, its config
//   masa_verify --model my_robot.xml --spec my.yaml  a robot you bring (joints only, no task code)
//   masa_verify ... --imperfection                   and how far from symmetric it is, limb by limb
// Prints the verdict and the worst observation entries and joints; exit 0 on pass, 1 on fail,
// 2 on bad input.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>

#include "common/core/build_info.hpp"
#include "common/config/run_config.hpp"
#include "common/core/config_error.hpp"
#include "common/physics_symmetry/imperfection_report.hpp"
#include "common/physics_symmetry/symmetry_verifier.hpp"
#include "tasks/tasks.hpp"

using namespace masa;

int main(int argc, char** argv) {
  CLI::App app{"Check step(T s, T a) = T step(s, a) and obs(T s) = T obs(s) by simulation"};
  app.set_version_flag("--version", masa::buildCommit());
  std::string task_name, model_file, spec_file;
  std::vector<std::string> overrides;
  task::SymmetryVerifierOptions opt;
  int top = 8;
  bool imperfection = false;
  app.add_option("--task", task_name, "a registered task (uses configs/tasks/<task>.yaml and its spec)");
  app.add_option("--model", model_file, "an MJCF file of your own robot (with --spec)");
  app.add_option("--spec", spec_file, "symmetry spec (default: the task's)");
  app.add_option("--set", overrides, "config override key.path=value (repeatable)");
  app.add_option("--states", opt.num_states, "random states to test")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--steps", opt.steps, "steps compared from each state")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--seed", opt.seed, "seed of the random states and actions")->capture_default_str();
  app.add_option("--tolerance", opt.tolerance, "largest error that passes")->capture_default_str();
  app.add_option("--top", top, "how many worst entries and joints to list")->capture_default_str();
  app.add_flag("--imperfection", imperfection,
               "also report how far from symmetric the model is, limb by limb and term by term");
  CLI11_PARSE(app, argc, argv);

  try {
    if (task_name.empty() == model_file.empty()) {
      std::cerr << "masa_verify: give either --task or --model (with --spec)\n";
      return 2;
    }
    std::unique_ptr<task::TaskFactory> factory;
    if (!task_name.empty()) {
      overrides.insert(overrides.begin(), "task=" + task_name);
      const auto rc = config::loadRunConfig(config::defaultConfigsDir(), overrides);
      const auto spec = sym::SymmetrySpec::load(spec_file.empty() ? rc.spec_path : spec_file);
      factory = std::make_unique<task::TaskFactory>(task::taskCatalog(), rc.task, spec, rc.env, rc.origin);
    } else {
      if (spec_file.empty()) {
        std::cerr << "masa_verify: --model needs --spec\n";
        return 2;
      }
      YAML::Node env;
      // Relative to where the user stands, not to the source tree (the registry's base for its tasks).
      env["model_file"] = std::filesystem::absolute(model_file).string();
      factory = std::make_unique<task::TaskFactory>(task::taskCatalog(), "mjcf", sym::SymmetrySpec::load(spec_file), env,
                                                    std::map<std::string, std::string>{}, "command line");
    }
    const auto report = task::verifySymmetry(*factory, opt);
    std::cout << report.summary(top);
    if (imperfection) std::cout << task::imperfectionReport(*factory, opt).summary(top);
    if (!model_file.empty()) std::cout << "  (no task code: observations and rewards were not checked)\n";
    return report.passed() ? 0 : 1;
  } catch (const ConfigError& e) {
    std::cerr << "masa_verify: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "masa_verify: " << e.what() << "\n";
    return 2;
  }
}
