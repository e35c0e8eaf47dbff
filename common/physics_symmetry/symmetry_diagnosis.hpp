// Names the culprit when a symmetry spec fails the physics. One wrong sign on a floating-base robot
// spreads through the contacts within one step, so the step alone shows errors at every joint. The
// parts of the step are checked first, in order, each joint by joint (joint r at T s against the
// image of its source joint c at s, with the spec's sign):
//   1. kinematics   every hinge and slide at 0 (the model's written pose), free joints as sampled:
//                   joint r's anchor must be g times c's, its axis g times c's times the sign (and
//                   times det g for a hinge, whose axis is axial). An axis that comes out reversed
//                   is a sign; an anchor that lands on another joint is a permutation (the binding
//                   the physics implies is proposed); one that lands on no joint is a group axis
//                   (another axis maps every joint), a group order (a smaller rotation holds), or
//                   the model itself.
//   2. actuation    qfrc_actuator(T s, T a) = P qfrc_actuator(s, a)   (gear, ctrlrange, gains)
//   3. mass matrix  M(T s) = P M(s) P^T                                (masses, inertias, armature)
//   4. bias forces  qfrc_bias(T s) = P qfrc_bias(s)                    (gravity, Coriolis)
//   5. passive      qfrc_passive(T s) = P qfrc_passive(s)              (damping, springs)
// with P the joint-space map of T (Task::velocityMap). The first part that breaks names the joint
// that takes part in most of its broken pairs, with the likely fix.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "common/sim/registry.hpp"

namespace masa::task {

struct NamedError {
  std::string name;
  double error = 0.0;
};

enum class Fix { kNone, kSign, kPermutation, kJointAxis, kGroupAxis, kGroupOrder, kModel };
std::string fixName(Fix fix);  // "sign", "permutation", "joint axis", "group axis", "group order", "model"

struct PartCheck {
  std::string name;               // "kinematics", "actuation", "mass matrix", "bias forces", "passive forces"
  double worst = 0.0;             // kinematics: metres and unit axes; forces relative, |d| / (1 + |want|)
  std::vector<NamedError> joints;  // per MuJoCo joint (the joint T writes)
};

struct Culprit {
  std::string part;    // the first part that breaks
  std::string joint;   // MuJoCo joint name
  std::string action;  // the spec's action dimension driving it, e.g. "limb1.hip" (empty for free joints)
  Fix fix = Fix::kNone;
  std::string advice;  // the likely fix, in words
};

struct Diagnosis {
  std::vector<PartCheck> parts;
  std::optional<Culprit> culprit;
  double tolerance = 0.0;
  std::string summary() const;
};

struct DiagnosisOptions {
  int num_states = 5;
  int max_warmup_steps = 60;
  std::uint64_t seed = 0;
  double tolerance = 1e-6;
};

Diagnosis diagnoseSymmetry(const TaskFactory& factory, const DiagnosisOptions& options = {});

}  // namespace masa::task
