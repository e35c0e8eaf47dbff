// Puts a candidate of the symmetry finder to the physics: builds the YAML task the finder writes
// for it (found_spec_writer.hpp) and runs the physics verifier on it, so that the observation map,
// the dynamics and the parts of the step are all checked, as for a shipped task.
#pragma once

#include <string>

#include "common/physics_symmetry/symmetry_finder.hpp"
#include "common/physics_symmetry/symmetry_verifier.hpp"

namespace masa::task {

struct CandidateCheck {
  bool confirmed = false;
  std::string error;      // the task could not be built (a kind its source refuses), else empty
  SymmetryReport report;  // valid when error is empty
};

CandidateCheck checkCandidate(const FoundSymmetries& found, const SymmetryCandidate& candidate,
                              const SymmetryVerifierOptions& options = {});

}  // namespace masa::task
