#include "common/physics_symmetry/symmetry_finder.hpp"

#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "common/symmetry/group_element.hpp"
#include "common/physics_symmetry/joint_slot_names.hpp"
#include "common/sim/mujoco_model.hpp"

namespace masa::task {
namespace {

const char* kAxisNames[] = {"x", "y", "z"};

std::string jointName(const mjModel* m, int j) {
  const char* n = mj_id2name(m, mjOBJ_JOINT, j);
  return n && *n ? n : "";
}

std::string label(const sym::Group& g) {
  const std::string axis = kAxisNames[static_cast<int>(g.axis)];
  if (g.type == sym::GroupType::kReflection) return "mirror, normal " + axis;
  return "rotation C" + std::to_string(g.order) + " about " + axis;
}

bool inSubtree(const mjModel* m, int body, int root) {
  for (int b = body; b > 0; b = m->body_parentid[b])
    if (b == root) return true;
  return root == 0;
}

// What the finder reads of the model: its actuated joints and their frames at the written pose
// (every hinge and slide at 0, free joints at qpos0), relative to the point the group keeps.
struct ModelFacts {
  const mjModel* m = nullptr;
  std::string path;
  std::vector<int> joints;            // actuated hinges and slides, in actuator (action) order
  std::vector<std::string> binding;   // per MuJoCo joint: the name the spec binds it by
  std::vector<FoundFreeJoint> free_joints;
  std::vector<Eigen::Vector3d> anchor, axis, com, subtree_com;  // per MuJoCo joint
  std::vector<Eigen::Vector3d> base_com;  // robot bases' own centres of mass: they must stay put
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
};

[[noreturn]] void refuse(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

// Reads the actuators and joints; refuses what a spec's `mujoco` binding cannot express.
void readJoints(ModelFacts& f) {
  const mjModel* m = f.m;
  std::vector<int> actuator_of(m->njnt, -1);
  f.binding.assign(m->njnt, "");
  for (int a = 0; a < m->nu; ++a) {
    const char* an = mj_id2name(m, mjOBJ_ACTUATOR, a);
    const std::string actuator = an && *an ? "'" + std::string(an) + "'" : "number " + std::to_string(a);
    if (m->actuator_trntype[a] != mjTRN_JOINT)
      refuse(f.path, "actuator " + actuator +
                         " drives a tendon, site or body, not a joint: the symmetry spec binds each action to a joint's actuator");
    const int j = m->actuator_trnid[2 * a];
    if (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE)
      refuse(f.path, "actuator " + actuator + " drives a ball or free joint: only hinges and slides can be actions");
    if (actuator_of[j] >= 0)
      refuse(f.path, "joint '" + jointName(m, j) + "' is driven by two actuators: the spec binds one actuator per joint");
    actuator_of[j] = a;
    f.joints.push_back(j);
    f.binding[j] = an && *an ? std::string(an) : jointName(m, j);
    if (f.binding[j].empty())
      refuse(f.path, "actuator " + actuator + " and the joint it drives have no name: the spec binds them by name");
  }
  for (int j = 0; j < m->njnt; ++j) {
    const int t = m->jnt_type[j];
    if (t == mjJNT_BALL)
      refuse(f.path, "joint '" + jointName(m, j) + "' is a ball joint: the symmetry spec moves hinges, slides and free joints only");
    if ((t == mjJNT_HINGE || t == mjJNT_SLIDE) && actuator_of[j] < 0)
      refuse(f.path, "joint '" + jointName(m, j) +
                         "' has no actuator: the spec moves each hinge and slide with the action of the actuator that drives it");
  }
  if (f.joints.empty()) refuse(f.path, "the model has no actuated joint: there is nothing for a symmetry to permute");
  for (int j = 0; j < m->njnt; ++j) {
    if (m->jnt_type[j] != mjJNT_FREE) continue;
    FoundFreeJoint fj;
    fj.joint = jointName(m, j);
    fj.body = mj_id2name(m, mjOBJ_BODY, m->jnt_bodyid[j]) ? mj_id2name(m, mjOBJ_BODY, m->jnt_bodyid[j]) : "";
    if (fj.joint.empty() || fj.body.empty())
      refuse(f.path, "a free joint or its body has no name: the spec lists free joints by name");
    for (int a : f.joints)
      if (inSubtree(m, m->jnt_bodyid[a], m->jnt_bodyid[j])) fj.kind = sym::FreeJointKind::kRobotBase;
    f.free_joints.push_back(fj);
  }
}

// Frames at the written pose, relative to the first robot base's position (else the origin).
void readFrames(ModelFacts& f) {
  const mjModel* m = f.m;
  mjData* d = mj_makeData(m);
  mju_copy(d->qpos, m->qpos0, m->nq);
  for (int j : f.joints) d->qpos[m->jnt_qposadr[j]] = 0.0;
  mj_kinematics(m, d);
  mj_comPos(m, d);
  auto vec = [](const mjtNum* p) { return Eigen::Vector3d(p[0], p[1], p[2]); };
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  std::vector<int> bases;
  for (const auto& fj : f.free_joints)
    if (fj.kind == sym::FreeJointKind::kRobotBase) bases.push_back(mj_name2id(m, mjOBJ_BODY, fj.body.c_str()));
  if (!bases.empty()) centre = vec(d->xpos + 3 * bases[0]);
  f.anchor.resize(m->njnt);
  f.axis.resize(m->njnt);
  f.com.resize(m->njnt);
  f.subtree_com.resize(m->njnt);
  for (int j : f.joints) {
    const int b = m->jnt_bodyid[j];
    f.anchor[j] = vec(d->xanchor + 3 * j) - centre;
    f.axis[j] = vec(d->xaxis + 3 * j);
    f.com[j] = vec(d->xipos + 3 * b) - centre;
    f.subtree_com[j] = vec(d->subtree_com + 3 * b) - centre;
  }
  for (int b : bases) f.base_com.push_back(vec(d->xipos + 3 * b) - centre);
  f.gravity = vec(m->opt.gravity);
  mj_deleteData(d);
}

// image[j]: the joint at g times joint j's frame; sign[j]: +1 when its axis is that image, -1 when reversed.
struct JointMap {
  std::vector<int> image, sign;
  std::string failure;  // empty when every actuated joint has an image
};

bool near(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tol) { return (a - b).norm() <= tol; }
bool sameValue(double a, double b, double tol) { return std::abs(a - b) <= tol * (1.0 + std::abs(a)); }

JointMap mapJoints(const ModelFacts& f, const Eigen::Matrix3d& g, bool mirror, double tol) {
  const mjModel* m = f.m;
  JointMap map;
  map.image.assign(m->njnt, -1);
  map.sign.assign(m->njnt, 0);
  if (!near(g * f.gravity, f.gravity, tol * (1.0 + f.gravity.norm()))) {
    map.failure = "it turns gravity";
    return map;
  }
  for (const auto& c : f.base_com)
    if (!near(g * c, c, tol)) {
      map.failure = "the robot base's centre of mass does not stay in place";
      return map;
    }
  std::vector<bool> taken(m->njnt, false);
  for (int j : f.joints) {
    // An axial vector (a hinge axis) picks up det g = -1 under a mirror; a slide's axis does not.
    const double axial = (mirror && m->jnt_type[j] == mjJNT_HINGE) ? -1.0 : 1.0;
    const Eigen::Vector3d want = axial * (g * f.axis[j]);
    std::string why = "no actuated joint sits at the image of joint '" + jointName(m, j) + "'";
    for (int k : f.joints) {
      if (taken[k] || m->jnt_type[k] != m->jnt_type[j] || !near(f.anchor[k], g * f.anchor[j], tol)) continue;
      const int sign = near(f.axis[k], want, tol) ? 1 : near(f.axis[k], -want, tol) ? -1 : 0;
      if (sign == 0) {
        why = "joint '" + jointName(m, k) + "' sits at the image of joint '" + jointName(m, j) +
              "' but its axis is not the image of that joint's axis";
        continue;
      }
      const int bj = m->jnt_bodyid[j], bk = m->jnt_bodyid[k];
      if (!sameValue(m->body_mass[bj], m->body_mass[bk], tol) ||
          !sameValue(m->body_subtreemass[bj], m->body_subtreemass[bk], tol) || !near(f.com[k], g * f.com[j], tol) ||
          !near(f.subtree_com[k], g * f.subtree_com[j], tol)) {
        why = k == j ? "joint '" + jointName(m, j) + "' is its own image, but the centre of mass of the body it moves is not"
                     : "joints '" + jointName(m, j) + "' and '" + jointName(m, k) +
                           "' correspond, but the bodies they move differ in mass or centre of mass";
        continue;
      }
      // A joint limit is part of the motion: the image's range is this range, negated with the sign.
      const double lo = m->jnt_range[2 * j], hi = m->jnt_range[2 * j + 1];
      const double want_lo = sign > 0 ? lo : -hi, want_hi = sign > 0 ? hi : -lo;
      if (m->jnt_limited[j] != m->jnt_limited[k] ||
          (m->jnt_limited[j] && (!sameValue(m->jnt_range[2 * k], want_lo, tol) ||
                                 !sameValue(m->jnt_range[2 * k + 1], want_hi, tol)))) {
        why = "joints '" + jointName(m, j) + "' and '" + jointName(m, k) + "' correspond, but their ranges differ" +
              (sign < 0 ? " (with the sign their axes need)" : "");
        continue;
      }
      map.image[j] = k;
      map.sign[j] = sign;
      taken[k] = true;
      break;
    }
    if (map.image[j] < 0) {
      map.failure = why;
      return map;
    }
  }
  return map;
}

// The joints that one joint visits under repeated g: [j, g j, g^2 j, ...].
std::vector<int> orbitOf(const JointMap& map, int j) {
  std::vector<int> orbit{j};
  for (int k = map.image[j]; k != j; k = map.image[k]) orbit.push_back(k);
  return orbit;
}

// Picks limb 0 of the first limb orbit: by name (right; lowest number), else by geometry.
int chooseFirstLimbJoint(const ModelFacts& f, const sym::Group& group, const std::vector<int>& orbit, std::string& cue) {
  std::vector<std::string> names;
  for (int j : orbit) names.push_back(f.binding[j]);
  if (group.type == sym::GroupType::kReflection) {
    const int a = sideOfName(names[0]), b = sideOfName(names[1]);
    if (a * b == -1) {
      cue = "names: '" + names[a > 0 ? 0 : 1] + "' says right, its side is limb 0";
      return orbit[a > 0 ? 0 : 1];
    }
    const int n = static_cast<int>(group.axis);
    const double c0 = f.subtree_com[orbit[0]][n];
    cue = std::string("geometry: the names say no side, limb 0 is the side at ") + kAxisNames[n] + " < 0";
    return c0 <= 0.0 ? orbit[0] : orbit[1];
  }
  if (const auto numbers = limbNumbers(names)) {
    const auto lowest = std::min_element(numbers->begin(), numbers->end()) - numbers->begin();
    cue = "names: the lowest numbered ('" + names[lowest] + "') is limb 0, the others counter-clockwise";
    return orbit[lowest];
  }
  cue = "order: the first actuator's joint ('" + names[0] + "') is limb 0, the others counter-clockwise";
  return orbit[0];
}

// Which member of an orbit belongs to limb 0: one on a chain with a joint already there (the
// same leg), else the one on the same side (mirror) or nearest in angle (rotation) as limb 0.
int limbZeroMember(const ModelFacts& f, const sym::Group& group, const std::vector<int>& orbit,
                   const std::vector<int>& limb0) {
  const mjModel* m = f.m;
  for (int k : orbit)
    for (int j : limb0) {
      const int bk = m->jnt_bodyid[k], bj = m->jnt_bodyid[j];
      if (inSubtree(m, bk, bj) || inSubtree(m, bj, bk)) return k;
    }
  const int n = static_cast<int>(group.axis);
  const Eigen::Vector3d ref = f.subtree_com[limb0[0]];
  if (group.type == sym::GroupType::kReflection)
    return (f.subtree_com[orbit[0]][n] <= 0.0) == (ref[n] <= 0.0) ? orbit[0] : orbit[1];
  // The angle about the axis between the member's centre of mass and limb 0's.
  auto planar = [&](Eigen::Vector3d v) {
    v[n] = 0.0;
    return v;
  };
  int best = orbit[0];
  double best_cos = -2.0;
  for (int k : orbit) {
    const Eigen::Vector3d a = planar(f.subtree_com[k]), b = planar(ref);
    const double c = a.dot(b) / std::max(1e-12, a.norm() * b.norm());
    if (c > best_cos) best_cos = c, best = k;
  }
  return best;
}

// Central joints (their own image), and limbs from the orbits of N joints; empty on success,
// else why the joint map is not a spec's layout.
std::string assignLimbs(const ModelFacts& f, const JointMap& map, SymmetryCandidate& c) {
  const mjModel* m = f.m;
  const int n = c.group.order;
  std::vector<bool> seen(m->njnt, false);
  std::vector<std::vector<int>> orbits;
  for (int j : f.joints) {
    if (seen[j]) continue;
    const auto orbit = orbitOf(map, j);
    for (int k : orbit) seen[k] = true;
    const int size = static_cast<int>(orbit.size());
    if (size == 1) {
      FoundSlot s;
      s.kind = map.sign[j] > 0 ? sym::EntryKind::kInvariant : sym::EntryKind::kOdd;
      s.joints = {j};
      c.central.push_back(s);
    } else if (size != n) {
      return "joint '" + jointName(m, j) + "' comes back to itself after " + std::to_string(size) + " of the " +
             std::to_string(n) + " steps: its joints do not form " + std::to_string(n) + " limbs";
    } else {
      orbits.push_back(orbit);
    }
  }
  if (orbits.empty()) return "every joint is its own image: there are no limbs to exchange";
  std::vector<int> limb0{chooseFirstLimbJoint(f, c.group, orbits[0], c.limb_cue)};
  for (size_t o = 1; o < orbits.size(); ++o) limb0.push_back(limbZeroMember(f, c.group, orbits[o], limb0));
  // Action order inside a limb: the actuator order of limb 0's joints.
  auto actuatorRank = [&](int j) { return std::find(f.joints.begin(), f.joints.end(), j) - f.joints.begin(); };
  std::sort(limb0.begin(), limb0.end(), [&](int a, int b) { return actuatorRank(a) < actuatorRank(b); });
  for (int j0 : limb0) {
    FoundSlot s;
    int sign = 1;
    for (int k = 0, j = j0; k < n; ++k, j = map.image[j]) {
      s.joints.push_back(j);
      s.limb_signs.push_back(sign);
      sign *= map.sign[j];
    }
    if (sign != 1) return "the axes of joint '" + jointName(m, j0) + "' and its images do not close around the axis";
    if (c.group.type == sym::GroupType::kReflection) {
      // Limb 1 is the mirror image of limb 0: the same angle is the same motion when the axis is
      // the axial image, and the opposite one when it is reversed.
      s.kind = map.sign[j0] > 0 ? sym::EntryKind::kInvariant : sym::EntryKind::kOdd;
      s.limb_signs.clear();
    } else if (std::all_of(s.limb_signs.begin(), s.limb_signs.end(), [](int v) { return v == 1; })) {
      s.limb_signs.clear();
    }
    c.limb.push_back(s);
  }
  // Names: the actuators' (else the joints'), with what differs between limbs dropped.
  std::vector<std::vector<std::string>> names;
  for (auto* block : {&c.central, &c.limb})
    for (auto& s : *block) {
      for (int j : s.joints) s.binding.push_back(f.binding[j]);
      names.push_back(s.binding);
    }
  const auto slot = slotNames(names);
  size_t i = 0;
  for (auto* block : {&c.central, &c.limb})
    for (auto& s : *block) s.name = slot[i++];
  return "";
}

SymmetryCandidate tryGroup(const ModelFacts& f, const sym::Group& group, double tol) {
  SymmetryCandidate c;
  c.group = group;
  c.label = label(group);
  c.free_joints = f.free_joints;
  const bool mirror = group.type == sym::GroupType::kReflection;
  // The generator that carries limb k onto limb k + 1: the mirror, or a turn by +2 pi / N (T_(N-1)).
  const Eigen::Matrix3d g = sym::spatialMap(group, mirror ? 1 : group.order - 1);
  const JointMap map = mapJoints(f, g, mirror, tol);
  c.reason = map.failure.empty() ? assignLimbs(f, map, c) : map.failure;
  c.proposed = c.reason.empty();
  if (!c.proposed) c.central.clear(), c.limb.clear();
  return c;
}

}  // namespace

std::vector<const SymmetryCandidate*> FoundSymmetries::proposed() const {
  std::vector<const SymmetryCandidate*> out;
  for (const auto& c : candidates)
    if (c.proposed) out.push_back(&c);
  std::stable_sort(out.begin(), out.end(), [](auto* a, auto* b) { return a->group.order > b->group.order; });
  return out;
}

FoundSymmetries findSymmetries(const std::string& model_path, const SymmetryFinderOptions& options) {
  const auto model = MujocoModel::load(model_path);
  ModelFacts f;
  f.m = model->get();
  f.path = model_path;
  readJoints(f);
  readFrames(f);

  FoundSymmetries out;
  out.model_path = model_path;
  out.model_name = identifier(f.m->names);  // MuJoCo stores the model's name first
  if (out.model_name.empty()) out.model_name = identifier(std::filesystem::path(model_path).stem().string());
  if (out.model_name.empty()) out.model_name = "robot";
  for (int a = 0; a < 3; ++a)
    out.candidates.push_back(tryGroup(f, {sym::GroupType::kReflection, static_cast<sym::Axis>(a), 2}, options.tolerance));
  // Per rotation axis the largest order that holds (its subgroups hold with it).
  for (int a = 0; a < 3; ++a) {
    bool found = false;
    for (int n = options.max_rotation_order; n >= 2 && !found; --n) {
      auto c = tryGroup(f, {sym::GroupType::kRotation, static_cast<sym::Axis>(a), n}, options.tolerance);
      if (c.proposed) {
        out.candidates.push_back(c);
        found = true;
      } else if (n == 2) {
        c.label = std::string("rotation about ") + kAxisNames[a];
        c.reason = "not even C2: " + c.reason;
        out.candidates.push_back(c);
      }
    }
  }
  return out;
}

}  // namespace masa::task
