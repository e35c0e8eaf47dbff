// A robot's symmetry, loaded from YAML and compiled to sparse linear maps T_i.
//
// Vector layout (observations and actions alike): the central block first, then N limb blocks of
// identical layout, limb 0 .. limb N-1. For a rotation group, limb k sits at angle 2*pi*k/N about
// the axis; for a reflection, limb 1 is the mirror image of limb 0.
//
// T_i maps the world so that agent i's frame lands on agent 0's (T_0 = I, T_i T_j = T_(i+j mod N)):
//   central'        = K_i(central)
//   limb block k'   = s_k * K_i(s_(k+i) * limb block (k+i mod N))
// where K_i is the per-entry action of the group element (kind below) and s_k the optional
// per-limb sign convention of an entry (limb_signs, default all +1).
//
// Entry kinds and their generator action (reflection with mirror normal n = axis; rotation by
// -2*pi/N about axis):
//   invariant           1 value, unchanged
//   odd                 1 value, sign flips per generator (needs an even group order)
//   polar_x|y|z         1 component of a polar vector (position, linear velocity)
//   axial_x|y|z         1 component of an axial vector (angular velocity, torque axis)
//                       (single components are closed only under reflection, or for the rotation axis)
//   vector3             polar 3-vector (x, y, z)
//   axial3              axial 3-vector: under reflection picks up det(M) = -1
//   vector2             (x, y) of a polar vector; rotation about z or a reflection
//   quaternion          (w, x, y, z) body orientation: reflection (w, -M v); rotation: left
//                       multiplication by a yaw quaternion lifted so that T_N = I (odd N only;
//                       even N has no such lift, use vectors such as projected gravity instead)
// An entry may repeat a 1-D kind: {name: arm_pos, kind: odd, count: 3}.
// A 1-D central entry of a reflection may name a partner, {name: a, kind: invariant, swap_with: b}:
// the generator then swaps a and b (each with its kind's sign), so central blocks are signed
// permutations in general, not only sign flips.
#pragma once

#include <string>
#include <vector>

#include "common/symmetry/sparse_map.hpp"

namespace YAML {
class Node;
}

namespace masa::sym {

enum class GroupType { kReflection, kRotation };
enum class Axis { kX = 0, kY = 1, kZ = 2 };

enum class EntryKind {
  kInvariant,
  kOdd,
  kPolarX,
  kPolarY,
  kPolarZ,
  kAxialX,
  kAxialY,
  kAxialZ,
  kVector3,
  kAxial3,
  kVector2,
  kQuaternion,
};

int entryKindSize(EntryKind kind);  // 1, 3, 2 or 4 values per instance
std::string entryKindName(EntryKind kind);

struct Entry {
  std::string name;
  EntryKind kind = EntryKind::kInvariant;
  int count = 1;                // repeats of a 1-D kind
  std::vector<int> limb_signs;  // limb entries only: N values of +1/-1 (empty = all +1)
  std::string swap_with;        // central 1-D entries of a reflection only: partner entry name
  int offset = 0;               // first index inside its block
  int size() const { return entryKindSize(kind) * count; }
};

struct BlockLayout {
  std::vector<Entry> central;
  std::vector<Entry> limb;  // layout of ONE limb block
  int centralDim() const;
  int limbDim() const;
};

// Optional tie to a MuJoCo model (spec key `mujoco`): which actuator each action drives, and how
// the model's free joints move under the group. The tasks map actions to actuators with it and the
// physics verifier transforms whole simulator states with it (hinge joints follow their actuator's
// action entry: same permutation, same sign).
enum class FreeJointKind {
  kRobotBase,  // floating base whose limbs are relabelled: orientation g R g^-1 (mirror: M R M)
  kObject,     // rigid object carried along: orientation g R (mirror: M R M, needs a mirror-symmetric object)
};

struct FreeJoint {
  std::string name;
  FreeJointKind kind = FreeJointKind::kObject;
};

struct MujocoBinding {
  bool present = false;
  std::vector<std::string> central_actuators;             // action order
  std::vector<std::vector<std::string>> limb_actuators;   // [limb][slot], action order
  std::vector<FreeJoint> free_joints;
};

struct Group {
  GroupType type = GroupType::kReflection;
  Axis axis = Axis::kY;
  int order = 2;  // N: 2 for a reflection
};

class SymmetrySpec {
 public:
  // Throws masa::ConfigError naming the file and the key (e.g. "observation.limb[2].kind").
  static SymmetrySpec load(const std::string& yaml_path);
  static SymmetrySpec parse(const YAML::Node& root, const std::string& source_name);
  static SymmetrySpec parseString(const std::string& yaml_text, const std::string& source_name = "<string>");

  const std::string& name() const { return name_; }
  const Group& group() const { return group_; }
  int numAgents() const { return group_.order; }

  const BlockLayout& observationLayout() const { return obs_; }
  const BlockLayout& actionLayout() const { return act_; }
  int obsDim() const;
  int actDim() const;
  int obsCentralDim() const { return obs_.centralDim(); }
  int obsLimbDim() const { return obs_.limbDim(); }
  int actCentralDim() const { return act_.centralDim(); }
  int actLimbDim() const { return act_.limbDim(); }

  // T_i, i in [0, N): obsDim x obsDim and actDim x actDim.
  const SparseMap& obsTransform(int i) const;
  const SparseMap& actTransform(int i) const;
  // T_i^-1 = T_(N-i mod N).
  const SparseMap& obsInverse(int i) const { return obsTransform((numAgents() - i) % numAgents()); }
  const SparseMap& actInverse(int i) const { return actTransform((numAgents() - i) % numAgents()); }

  // Orbit classes: dimensions mixed by any T_i get the same class id (0..numClasses-1). Shared
  // variances (normalizers) and shared standard deviations (policy) are tied per class.
  const std::vector<int>& obsClasses() const { return obs_classes_; }
  const std::vector<int>& actClasses() const { return act_classes_; }

  // Human-readable name of each dimension, e.g. "limb1.knee_pos" or "central.torso_lin_vel[2]".
  const std::vector<std::string>& obsNames() const { return obs_names_; }
  const std::vector<std::string>& actNames() const { return act_names_; }

  const MujocoBinding& mujoco() const { return mujoco_; }
  // Actuator names in action order (central, then limb 0, limb 1, ...); throws if no binding.
  std::vector<std::string> actuatorsInActionOrder() const;
  const std::string& source() const { return source_; }

 private:
  std::string name_;
  std::string source_;
  Group group_;
  BlockLayout obs_, act_;
  std::vector<SparseMap> obs_t_, act_t_;
  std::vector<int> obs_classes_, act_classes_;
  std::vector<std::string> obs_names_, act_names_;
  MujocoBinding mujoco_;
};

}  // namespace masa::sym
