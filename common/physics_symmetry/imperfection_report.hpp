// How far from symmetric an almost-symmetric robot is (issue #13 item 4): the model's parameters
// limb by limb, term by term (mass, inertia, centre of mass offset, damping, armature, friction
// loss, stiffness, joint range, gear, control range of the body and joint each limb slot binds),
// each against the median over the limbs (so that one odd limb stands alone), with the one-step dynamics error and the parts of the step
// (symmetry_diagnosis.hpp) that the verifier measures. Tells a user how much MASA's exact symmetry
// approximates their robot.
#pragma once

#include <string>
#include <vector>

#include "common/physics_symmetry/symmetry_verifier.hpp"

namespace masa::task {

struct Imperfection {
  std::string term;   // "mass", "inertia", "com offset", "damping", ...
  int limb = 0;
  std::string joint;  // the joint the limb slot binds (its body for body terms)
  double value = 0.0, mean = 0.0;  // mean: the median over the limbs
  double relative = 0.0;  // |value - median| / |median|
};

struct ImperfectionReport {
  std::vector<Imperfection> entries;  // largest relative difference first
  SymmetryReport dynamics;            // the verifier's one-step errors and parts
  std::string summary(int top_k = 8) const;
};

// With env.randomization the model is that of an episode drawn from options.seed: per_limb draws
// show as the limbs whose masses, damping, gear, ... differ.
ImperfectionReport imperfectionReport(const TaskFactory& factory, const SymmetryVerifierOptions& options = {});

}  // namespace masa::task
