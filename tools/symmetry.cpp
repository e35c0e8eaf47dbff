// masa_symmetry: find a robot's symmetries from its model (docs/symmetry_finder.md).
//   masa_symmetry find robot.xml                          candidates: groups, limbs, joint permutation and signs
//   masa_symmetry find robot.xml --verify                 and which ones the physics confirms (masa_verify's checks)
//   masa_symmetry find robot.xml --out robot.yaml --task-out robot_task.yaml   the best one as a spec and a YAML task
// Exit status 0 when a candidate is proposed (with --verify: confirmed), 1 when none, 2 on bad input.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "common/core/build_info.hpp"
#include "common/physics_symmetry/found_spec_writer.hpp"
#include "common/physics_symmetry/symmetry_candidate_check.hpp"
#include "common/physics_symmetry/symmetry_finder.hpp"

using namespace masa;

namespace {

void printLayout(const task::SymmetryCandidate& c) {
  std::printf("      limbs: %s\n", c.limb_cue.c_str());
  auto row = [](const char* block, const task::FoundSlot& s) {
    std::string signs, joints;
    for (int v : s.limb_signs) signs += (signs.empty() ? "" : ", ") + std::to_string(v);
    for (const auto& b : s.binding) joints += (joints.empty() ? "" : ", ") + b;
    std::printf("      %-7s %-18s %-9s%s  %s\n", block, s.name.c_str(), sym::entryKindName(s.kind).c_str(),
                signs.empty() ? "" : (" [" + signs + "]").c_str(), joints.c_str());
  };
  for (const auto& s : c.central) row("central", s);
  for (const auto& s : c.limb) row("limb", s);
}

bool writeFile(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) std::cerr << "masa_symmetry: cannot write " << path << "\n";
  return static_cast<bool>(out);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Find a robot's symmetries (mirror planes, rotation axes) from its MJCF and write them as a spec"};
  app.set_version_flag("--version", masa::buildCommit());
  app.require_subcommand(1);
  auto* find = app.add_subcommand("find", "propose the symmetries of a model, optionally proven by simulation");
  std::string model_file, out_file, task_file;
  bool verify = false;
  task::SymmetryFinderOptions finder;
  task::SymmetryVerifierOptions opt;
  find->add_option("model", model_file, "MJCF file of the robot")->required();
  find->add_option("--out", out_file, "write the best candidate's spec here");
  find->add_option("--task-out", task_file, "write a YAML task config over that spec here (its observation sources)");
  find->add_flag("--verify", verify, "run the physics verifier on every candidate (as masa_verify does)");
  find->add_option("--states", opt.num_states, "random states per candidate for --verify")->capture_default_str();
  find->add_option("--seed", opt.seed, "seed of the random states and actions")->capture_default_str();
  find->add_option("--max-order", finder.max_rotation_order, "largest rotation order tried")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  try {
    const auto found = task::findSymmetries(model_file, finder);
    std::printf("%s (%s): %zu of %zu groups proposed by the geometry\n", model_file.c_str(), found.model_name.c_str(),
                found.proposed().size(), found.candidates.size());
    for (const auto& c : found.candidates) {
      if (!c.proposed) std::printf("  %-22s no: %s\n", c.label.c_str(), c.reason.c_str());
    }
    const task::SymmetryCandidate* best = nullptr;
    for (const auto* c : found.proposed()) {
      std::printf("  %-22s proposed: %zu limbs x %zu joints, %zu central\n", c->label.c_str(),
                  static_cast<size_t>(c->group.order), c->limb.size(), c->central.size());
      printLayout(*c);
      bool ok = true;
      if (verify) {
        const auto check = task::checkCandidate(found, *c, opt);
        ok = check.confirmed;
        if (!check.error.empty()) {
          std::printf("      physics: NOT CONFIRMED, the task could not be built: %s\n", check.error.c_str());
        } else {
          std::printf("      physics: %s (worst error %.1e, tolerance %.0e)\n", ok ? "CONFIRMED" : "NOT CONFIRMED",
                      check.report.worst(), check.report.tolerance);
          if (!ok) std::printf("%s", check.report.summary(3).c_str());
        }
      }
      if (ok && !best) best = c;
    }
    if (!best) {
      std::printf("no symmetry %s\n", verify ? "confirmed by the physics" : "proposed");
      return 1;
    }
    std::printf("best: %s%s\n", best->label.c_str(), verify ? " (confirmed)" : " (not verified: add --verify)");
    if (!out_file.empty()) {
      if (!writeFile(out_file, task::foundSpecYaml(found, *best))) return 2;
      std::printf("spec written to %s\n", out_file.c_str());
    }
    if (!task_file.empty() &&
        !writeFile(task_file, task::foundTaskYaml(found, *best,
                                                  out_file.empty() ? "<your spec file>"
                                                                   : std::filesystem::absolute(out_file).string())))
      return 2;
    if (!task_file.empty()) std::printf("YAML task written to %s\n", task_file.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "masa_symmetry: " << e.what() << "\n";
    return 2;
  }
}
