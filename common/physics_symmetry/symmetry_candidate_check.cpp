#include "common/physics_symmetry/symmetry_candidate_check.hpp"

#include "common/physics_symmetry/found_spec_writer.hpp"
#include "common/sim/yaml/yaml_task.hpp"

namespace masa::task {

CandidateCheck checkCandidate(const FoundSymmetries& found, const SymmetryCandidate& candidate,
                              const SymmetryVerifierOptions& options) {
  CandidateCheck check;
  try {
    const auto spec = sym::SymmetrySpec::parseString(foundSpecYaml(found, candidate), "proposed spec (" + candidate.label + ")");
    // A proposal is a task written in YAML (task_code: yaml) over the user's model.
    static const TaskCatalog yaml_only({{"yaml", "", &makeYamlTask}});
    const TaskFactory factory(yaml_only, found.model_name, spec, foundTaskEnv(found, candidate), {}, "proposed task");
    check.report = verifySymmetry(factory, options);
    check.confirmed = check.report.passed();
  } catch (const std::exception& e) {
    // A proposal the spec parser or the YAML task refuses is not confirmed; the reason is the report.
    check.error = e.what();
  }
  return check;
}

}  // namespace masa::task
