// Finds a robot's candidate symmetries from its MJCF alone: mirror planes and rotation axes through
// the root, each with the joint permutation, the signs and the limb assignment a spec needs.
//
// Geometry decides what maps to what: with every hinge and slide at 0 (the pose the model is
// written in), a group element g is a candidate when every actuated joint has an image joint whose
// anchor is g times its anchor, whose axis is +-g times its axis (times det g for a hinge, an axial
// vector), and whose moved body has the same mass and a centre of mass at g times the other's.
// The sign of the axis match is the joint's sign (kind `odd`, or `limb_signs` under a rotation).
// Names only choose among equally valid labellings: which side is limb 0 (the one named right,
// else the side at negative coordinate along the mirror normal), which leg is limb 0 (the one
// numbered lowest, else the first actuator's), and the entry names. What the geometry proposes the
// physics still has to confirm (symmetry_candidate_check.hpp): gravity, the world, contacts,
// actuators and damping are not looked at here beyond gravity's direction.
#pragma once

#include <string>
#include <vector>

#include "common/symmetry/symmetry_spec.hpp"

namespace masa::task {

// One action entry of a found spec: a central joint, or the same joint in every limb.
struct FoundSlot {
  std::string name;                                  // entry name, e.g. "hip_x" (from the joint names)
  sym::EntryKind kind = sym::EntryKind::kInvariant;  // invariant or odd
  std::vector<int> limb_signs;                       // rotation limbs: N values of +-1; empty = all +1
  std::vector<int> joints;                           // MuJoCo joint ids: central one, limb one per limb
  std::vector<std::string> binding;                  // the spec's binding name per joint (actuator, else joint)
};

// A free joint of the model and how the group moves it.
struct FoundFreeJoint {
  std::string joint, body;  // MuJoCo names
  sym::FreeJointKind kind = sym::FreeJointKind::kObject;  // robot_base: its subtree holds actuated joints
};

struct SymmetryCandidate {
  sym::Group group;
  std::string label;        // "mirror, normal y" or "rotation C4 about z"
  bool proposed = false;    // the geometry holds; the physics is checked separately
  std::string reason;       // why not, when not proposed
  std::string limb_cue;     // how limb 0 was chosen, for the report
  std::vector<FoundSlot> central, limb;
  std::vector<FoundFreeJoint> free_joints;
};

struct FoundSymmetries {
  std::string model_path;
  std::string model_name;                    // the spec name to use: the MJCF's model name, else the file stem
  std::vector<SymmetryCandidate> candidates; // mirrors x, y, z, then rotations about x, y, z
  // The proposed candidates, largest group first (a rotation C_N before a mirror when N > 2).
  std::vector<const SymmetryCandidate*> proposed() const;
};

struct SymmetryFinderOptions {
  int max_rotation_order = 8;  // rotations C_N, N = 2 .. this, the largest that holds per axis
  double tolerance = 1e-6;     // metres and unit-axis distance for "maps onto"
};

// Throws std::runtime_error naming the file for a missing file, an MJCF MuJoCo cannot load, or a
// model the spec format cannot bind (no actuated joint, an actuator on a tendon or site, a joint
// driven by two actuators, a hinge or slide without an actuator, a ball joint).
FoundSymmetries findSymmetries(const std::string& model_path, const SymmetryFinderOptions& options = {});

}  // namespace masa::task
