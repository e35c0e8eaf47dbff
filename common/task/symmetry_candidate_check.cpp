#include "common/task/symmetry_candidate_check.hpp"

#include "common/task/found_spec_writer.hpp"

namespace masa::task {

CandidateCheck checkCandidate(const FoundSymmetries& found, const SymmetryCandidate& candidate,
                              const SymmetryVerifierOptions& options) {
  CandidateCheck check;
  try {
    const auto spec = sym::SymmetrySpec::parseString(foundSpecYaml(found, candidate), "proposed spec (" + candidate.label + ")");
    const TaskFactory factory(found.model_name, spec, foundTaskEnv(found, candidate), {}, "proposed task");
    check.report = verifySymmetry(factory, options);
    check.confirmed = check.report.passed();
  } catch (const std::exception& e) {
    // A proposal the spec parser or the YAML task refuses is not confirmed; the reason is the report.
    check.error = e.what();
  }
  return check;
}

}  // namespace masa::task
