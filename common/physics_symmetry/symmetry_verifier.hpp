// Physics-symmetry verifier: proves (or refutes) a symmetry spec against the simulation.
//
// For random valid states s (reset, then a random number of random-action steps) and random
// actions a, and every group element i:
//   observation map:  obs(T_i s) = T_i obs(s)                     (the observation is equivariant)
//   dynamics:         step(T_i s, T_i a) = T_i step(s, a)          (per joint: qpos and qvel)
//   reward:           r(T_i s, T_i a) = r(s, a), same termination
// and reports the worst error per observation entry and per joint. Free-joint orientations are
// compared as rotations (q and -q are equal). The parts of the step are checked too, in order and
// joint by joint (symmetry_diagnosis.hpp), so that a wrong sign, a swapped limb, a wrong axis or a
// wrong group order is named at its joint with the likely fix even where the step spreads the error.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/sim/registry.hpp"
#include "common/physics_symmetry/symmetry_diagnosis.hpp"

namespace masa::task {

struct SymmetryVerifierOptions {
  int num_states = 20;
  int max_warmup_steps = 60;  // random-action steps from reset before a state is used
  int steps = 1;              // steps compared from each state
  int diagnosis_states = 5;   // states for the parts of the step (at most num_states)
  std::uint64_t seed = 0;
  double tolerance = 1e-6;    // pass threshold on every reported error (see docs/verifier.md)
};

struct SymmetryReport {
  // Observation errors are relative, |got - want| / (1 + |want|) (observations are floats);
  // joint errors are absolute, in the joint's units (m, rad, m/s, rad/s).
  std::vector<NamedError> observation_map;  // per observation dimension: obs(T s) vs T obs(s)
  std::vector<NamedError> observation;      // per observation dimension after the step(s)
  std::vector<NamedError> joints;           // per MuJoCo joint after the step(s) (qpos and qvel)
  double reward_error = 0.0;
  int termination_mismatches = 0;
  double tolerance = 0.0;
  Diagnosis parts;  // the parts of the step, in order, and the culprit when one breaks

  double worst() const;
  bool passed() const { return worst() <= tolerance && termination_mismatches == 0; }
  // Human-readable: verdict, the k worst observation entries and joints, the parts and the culprit.
  std::string summary(int top_k = 5) const;
};

SymmetryReport verifySymmetry(const TaskFactory& factory, const SymmetryVerifierOptions& options = {});

}  // namespace masa::task
