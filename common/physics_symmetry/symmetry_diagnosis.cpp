#include "common/physics_symmetry/symmetry_diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <sstream>

#include "common/symmetry/group_element.hpp"

namespace masa::task {
namespace {

enum class Verdict { kOk, kSign, kAxis, kPermutation, kNone };

// One joint T writes (target, at T s) against the joint it should come from (source, at s).
struct Pair {
  int element = 0;
  int target = -1, source = -1;
  Verdict verdict = Verdict::kOk;
  int partner = -1;  // kPermutation: the joint whose image the target's frame is
};

struct Frames {
  std::vector<Eigen::Vector3d> anchor, axis, com;  // per joint; com: its body's centre of mass
};

Frames jointFrames(const mjModel* m, const mjData* d) {
  Frames f;
  for (int j = 0; j < m->njnt; ++j) {
    f.anchor.emplace_back(d->xanchor[3 * j], d->xanchor[3 * j + 1], d->xanchor[3 * j + 2]);
    f.axis.emplace_back(d->xaxis[3 * j], d->xaxis[3 * j + 1], d->xaxis[3 * j + 2]);
    const mjtNum* c = d->xipos + 3 * m->jnt_bodyid[j];
    f.com.emplace_back(c[0], c[1], c[2]);
  }
  return f;
}

bool moves(const mjModel* m, int j) { return m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE; }

std::string jointName(const mjModel* m, int j) {
  const char* n = mj_id2name(m, mjOBJ_JOINT, j);
  return n ? n : "joint" + std::to_string(j);
}

// How far the target's frame at T s is from the image of the source's frame at s, with the source
// value multiplied by `sign`: {anchor (and body centre of mass) distance, axis distance, axis
// distance with the sign reversed}.
struct FrameError {
  double anchor, axis, reversed;
};

FrameError frameError(const mjModel* m, const Frames& at_t, const Frames& at_s, const Eigen::Matrix3d& g, bool mirror,
                      int target, int source, double sign) {
  const double axial = (m->jnt_type[source] == mjJNT_HINGE && mirror) ? -1.0 : 1.0;
  const Eigen::Vector3d want = sign * axial * (g * at_s.axis[source]);
  const double anchor = std::max((at_t.anchor[target] - g * at_s.anchor[source]).norm(),
                                 (at_t.com[target] - g * at_s.com[source]).norm());
  return {anchor, (at_t.axis[target] - want).norm(),
          (at_t.axis[target] + want).norm()};
}

// The joint whose image under g the target's frame is (either axis sign), or -1.
int findPartner(const mjModel* m, const Frames& at_t, const Frames& at_s, const Eigen::Matrix3d& g, bool mirror,
                int target, double tol) {
  for (int k = 0; k < m->njnt; ++k) {
    if (!moves(m, k) || m->jnt_type[k] != m->jnt_type[target]) continue;
    const FrameError e = frameError(m, at_t, at_s, g, mirror, target, k, 1.0);
    if (e.anchor <= tol && std::min(e.axis, e.reversed) <= tol) return k;
  }
  return -1;
}

// Every hinge and slide at 0: the pose the model is written in. T of it is again all zeros, so the
// frames at T s depend only on the free joints and on how the model is built, not on the spec's signs.
void zeroJoints(Task& t) {
  const mjModel* m = t.model();
  for (int j = 0; j < m->njnt; ++j)
    if (moves(m, j)) t.data()->qpos[m->jnt_qposadr[j]] = 0.0;
  mj_forward(m, t.data());
}

// With every hinge and slide at 0, does each bound joint land on some joint of the model under
// group element i of `group` (free joints moved by it)? Used to try another axis or element.
bool everyJointLands(const Task& zeroed, const sym::Group& group, int i, const std::vector<int>& bound, double tol) {
  const mjModel* m = zeroed.model();
  mjData* d = mj_makeData(m);
  std::copy(zeroed.data()->qpos, zeroed.data()->qpos + m->nq, d->qpos);
  std::vector<double> vel(6), warm(6);
  for (const auto& fj : zeroed.spec().mujoco().free_joints) {
    const int j = mj_name2id(m, mjOBJ_JOINT, fj.name.c_str());
    transformFreeJoint(group, i, fj.kind, d->qpos + m->jnt_qposadr[j], vel.data(), warm.data());
  }
  mj_kinematics(m, d);
  const Frames at_t = jointFrames(m, d), at_s = jointFrames(m, zeroed.data());
  mj_deleteData(d);
  const Eigen::Matrix3d g = sym::spatialMap(group, i);
  for (int j : bound)
    if (findPartner(m, at_t, at_s, g, sym::isMirror(group, i), j, tol) < 0) return false;
  return true;
}

struct Context {
  const mjModel* m;
  const sym::SymmetrySpec* spec;
  std::vector<int> action_joint;   // per action
  std::vector<int> joint_action;   // per joint, -1 when unbound
  std::vector<int> bound;          // bound joints
  double tol;
};

void raise(PartCheck& p, int joint, double e) {
  p.joints[joint].error = std::max(p.joints[joint].error, e);
  p.worst = std::max(p.worst, e);
}

// Kinematics of one sampled state under element i: each pair classified, errors per joint.
void checkKinematics(const Context& cx, const Task& zeroed, Task& transformed, int i, PartCheck& part,
                     std::vector<Pair>& pairs) {
  const mjModel* m = cx.m;
  transformed.copyStateFrom(zeroed);
  transformed.applySymmetry(i);
  const Frames at_s = jointFrames(m, zeroed.data()), at_t = jointFrames(m, transformed.data());
  const Eigen::Matrix3d g = sym::spatialMap(cx.spec->group(), i);
  const bool mirror = sym::isMirror(cx.spec->group(), i);
  const sym::SparseMap& t = cx.spec->actTransform(i);
  for (int r = 0; r < t.rows(); ++r) {
    const int begin = t.rowStart()[r];
    Pair p{i, cx.action_joint[r], cx.action_joint[t.colIndex()[begin]]};
    if (p.target < 0 || p.source < 0) continue;
    const FrameError e = frameError(m, at_t, at_s, g, mirror, p.target, p.source, t.values()[begin]);
    raise(part, p.target, std::max(e.anchor, e.axis));
    if (e.anchor <= cx.tol && e.axis <= cx.tol)
      p.verdict = Verdict::kOk;
    else if (e.anchor <= cx.tol && e.reversed <= cx.tol)
      p.verdict = Verdict::kSign;
    else if (e.anchor <= cx.tol)
      p.verdict = Verdict::kAxis;
    else if ((p.partner = findPartner(m, at_t, at_s, g, mirror, p.target, cx.tol)) >= 0)
      p.verdict = Verdict::kPermutation;
    else
      p.verdict = Verdict::kNone;
    pairs.push_back(p);
  }
}

// Generalized forces and the mass matrix at T s (with T a) against P times those at s (with a).
void checkForces(const Context& cx, Task& at_s, Task& at_t, int i, const Eigen::VectorXf& act, std::vector<PartCheck>& parts,
                 std::vector<Pair>& broken) {
  const mjModel* m = cx.m;
  const int nv = m->nv;
  Eigen::VectorXf tact(act.size());
  cx.spec->actTransform(i).apply<float>(act, tact);
  at_s.actuate(act.data());
  at_t.actuate(tact.data());
  mj_forward(m, at_s.data());
  mj_forward(m, at_t.data());
  const Eigen::MatrixXd p = at_t.velocityMap(i);
  auto vec = [&](const mjtNum* v) { return Eigen::Map<const Eigen::VectorXd>(v, nv); };
  Eigen::MatrixXd ms(nv, nv), mt(nv, nv);
  mj_fullM(m, ms.data(), at_s.data()->qM);  // symmetric: row- and column-major agree
  mj_fullM(m, mt.data(), at_t.data()->qM);
  const Eigen::MatrixXd want_m = p * ms * p.transpose();
  const std::vector<std::pair<Eigen::VectorXd, Eigen::VectorXd>> forces = {
      {vec(at_t.data()->qfrc_actuator), p * vec(at_s.data()->qfrc_actuator)},
      {Eigen::VectorXd(), Eigen::VectorXd()},  // mass matrix: rows below
      {vec(at_t.data()->qfrc_bias), p * vec(at_s.data()->qfrc_bias)},
      {vec(at_t.data()->qfrc_passive), p * vec(at_s.data()->qfrc_passive)}};
  const sym::SparseMap& t = cx.spec->actTransform(i);
  for (int k = 0; k < 4; ++k) {
    for (int d = 0; d < nv; ++d) {
      double e = 0.0;
      if (k == 1) {
        for (int c = 0; c < nv; ++c) e = std::max(e, std::abs(mt(d, c) - want_m(d, c)) / (1.0 + std::abs(want_m(d, c))));
      } else {
        e = std::abs(forces[k].first(d) - forces[k].second(d)) / (1.0 + std::abs(forces[k].second(d)));
      }
      const int j = m->dof_jntid[d];
      raise(parts[1 + k], j, e);
      if (e <= cx.tol) continue;
      Pair b{i, j, j, Verdict::kNone};
      b.partner = k;  // which part
      if (cx.joint_action[j] >= 0) b.source = cx.action_joint[t.colIndex()[t.rowStart()[cx.joint_action[j]]]];
      broken.push_back(b);
    }
  }
}

// The joint taking part in most pairs (as target or source), bound joints first; ties: lowest id.
int mostImplicated(const Context& cx, const std::vector<Pair>& pairs) {
  std::map<int, int> count;
  for (const Pair& p : pairs) {
    if (cx.joint_action[p.target] < 0 && p.target == p.source) continue;
    ++count[p.target];
    if (p.source != p.target) ++count[p.source];
  }
  if (count.empty()) return pairs.empty() ? -1 : pairs.front().target;
  int best = count.begin()->first;
  for (const auto& [j, c] : count)
    if (c > count[best]) best = j;
  return best;
}

std::string entryOf(const std::string& action_name) {  // "limb1.hip" -> "hip"
  const auto dot = action_name.find('.');
  return dot == std::string::npos ? action_name : action_name.substr(dot + 1);
}

std::string bindingName(const mjModel* m, int joint) {
  for (int a = 0; a < m->nu; ++a)
    if (m->actuator_trntype[a] == mjTRN_JOINT && m->actuator_trnid[2 * a] == joint) {
      const char* n = mj_id2name(m, mjOBJ_ACTUATOR, a);
      if (n) return n;
    }
  return jointName(m, joint);
}

Culprit signCulprit(const Context& cx, const std::vector<Pair>& pairs) {
  const int j = mostImplicated(cx, pairs);
  const std::string action = cx.spec->actNames()[cx.joint_action[j]];
  // One limb's own sign when this joint is in more broken pairs than any other joint.
  std::map<int, int> count;
  for (const Pair& p : pairs) {
    ++count[p.target];
    if (p.source != p.target) ++count[p.source];
  }
  bool alone = true;
  for (const auto& [k, c] : count)
    if (k != j && c >= count[j]) alone = false;
  Culprit c{"kinematics", jointName(cx.m, j), action, Fix::kSign, ""};
  const std::string entry = entryOf(action);
  if (alone && action.rfind("limb", 0) == 0)
    c.advice = "the sign of joint '" + c.joint + "' is wrong: flip " + action.substr(0, action.find('.')) +
               "'s entry of limb_signs of action '" + entry + "' (and of its observations), or reverse the joint's axis in the model";
  else
    c.advice = "the sign of action '" + entry + "' (joint '" + c.joint + "' and its images) is wrong: its kind flips " +
               "where the model does not, or the reverse (odd <-> invariant, or limb_signs), or one side's joint axis is reversed in the model";
  return c;
}

// The binding the physics implies: limb k+1 holds the joints T_1 carries onto limb k's.
Culprit permutationCulprit(const Context& cx, const std::vector<Pair>& pairs) {
  const sym::SymmetrySpec& spec = *cx.spec;
  const int n = spec.numAgents(), cd = spec.actCentralDim(), ld = spec.actLimbDim();
  std::vector<int> from(cx.m->njnt, -1);  // under T_1: the joint each joint's value should come from
  for (const Pair& p : pairs)
    if (p.element == 1 && from[p.target] < 0) from[p.target] = p.verdict == Verdict::kPermutation ? p.partner : p.source;
  std::vector<std::vector<int>> limbs(n, std::vector<int>(ld, -1));
  for (int s = 0; s < ld; ++s) limbs[0][s] = cx.action_joint[cd + s];
  for (int k = 1; k < n; ++k)
    for (int s = 0; s < ld; ++s) limbs[k][s] = limbs[k - 1][s] >= 0 ? from[limbs[k - 1][s]] : -1;
  std::ostringstream proposal;
  proposal << "[";
  int first_k = -1, first_s = -1;
  for (int k = 0; k < n; ++k) {
    proposal << (k ? ", [" : "[");
    for (int s = 0; s < ld; ++s) {
      proposal << (s ? ", " : "") << (limbs[k][s] >= 0 ? bindingName(cx.m, limbs[k][s]) : "?");
      if (first_k < 0 && limbs[k][s] != cx.action_joint[cd + k * ld + s]) first_k = k, first_s = s;
    }
    proposal << "]";
  }
  proposal << "]";
  if (first_k < 0) {  // the limbs chain up as bound: the permutation is in the central block
    const Pair& p = *std::find_if(pairs.begin(), pairs.end(), [](const Pair& q) { return q.verdict == Verdict::kPermutation; });
    return {"kinematics", jointName(cx.m, p.target), spec.actNames()[cx.joint_action[p.target]], Fix::kPermutation,
            "T_" + std::to_string(p.element) + " writes joint '" + jointName(cx.m, p.target) + "' from '" +
                jointName(cx.m, p.source) + "', but the model carries '" + jointName(cx.m, p.partner) + "' there"};
  }
  const int bound_joint = cx.action_joint[cd + first_k * ld + first_s];
  Culprit c{"kinematics", jointName(cx.m, bound_joint), spec.actNames()[cd + first_k * ld + first_s], Fix::kPermutation, ""};
  c.advice = "limb " + std::to_string(first_k) + " binds '" + bindingName(cx.m, bound_joint) + "' where the model's " +
             "symmetry puts '" + (limbs[first_k][first_s] >= 0 ? bindingName(cx.m, limbs[first_k][first_s]) : "?") +
             "': a permutation. The binding the physics implies (mujoco.actuators.limbs): " + proposal.str();
  return c;
}

// Some joint lands on no joint: try the other elements (a smaller rotation group) and other axes.
Culprit groupCulprit(const Context& cx, const Task& zeroed, const std::vector<Pair>& pairs) {
  const sym::Group& group = cx.spec->group();
  const int n = group.order;
  const Pair& first = *std::find_if(pairs.begin(), pairs.end(), [](const Pair& p) { return p.verdict == Verdict::kNone; });
  Culprit c{"kinematics", jointName(cx.m, first.target), cx.spec->actNames()[cx.joint_action[first.target]], Fix::kModel, ""};
  std::vector<int> holds;
  for (int i = 1; i < n; ++i)
    if (everyJointLands(zeroed, group, i, cx.bound, cx.tol)) holds.push_back(i);
  if (!holds.empty() && group.type == sym::GroupType::kRotation) {
    const int step = holds.front(), order = n / std::gcd(n, step);
    c.fix = Fix::kGroupOrder;
    c.advice = "T_" + std::to_string(step) + " (" + std::to_string(360 * step / n) + " deg) maps every joint onto a joint, T_" +
               std::to_string(first.element) + " (" + std::to_string(360 * first.element / n) + " deg) puts joint '" +
               c.joint + "' where the model has none: the model's group looks like C" + std::to_string(order) +
               ", not C" + std::to_string(n) + " (group order " + std::to_string(order) + ", limbs regrouped)";
    return c;
  }
  const char* axes = "xyz";
  for (int a = 0; a < 3; ++a) {
    if (a == static_cast<int>(group.axis)) continue;
    sym::Group alt = group;
    alt.axis = static_cast<sym::Axis>(a);
    bool all = true;
    for (int i = 1; i < n && all; ++i) all = everyJointLands(zeroed, alt, i, cx.bound, cx.tol);
    if (!all) continue;
    c.fix = Fix::kGroupAxis;
    c.advice = std::string("the group's axis is wrong: about '") + axes[static_cast<int>(group.axis)] + "' joint '" +
               c.joint + "' lands where the model has no joint; about '" + axes[a] +
               "' every joint lands on one (group.axis: " + axes[a] + ")";
    return c;
  }
  c.advice = "under T_" + std::to_string(first.element) + " joint '" + c.joint +
             "' lands where the model has no joint, for every axis: the model's geometry (body positions) is not symmetric there";
  return c;
}

Culprit forceCulprit(const Context& cx, const std::vector<Pair>& broken, int part_index, const std::string& part) {
  std::vector<Pair> these;
  for (const Pair& b : broken)
    if (b.partner == part_index) these.push_back(b);
  const int j = mostImplicated(cx, these);
  static const char* what[] = {"its actuator (gear, ctrlrange, gains, or the task's control law)",
                               "the inertia it moves (masses, inertias, armature of its bodies and those below)",
                               "gravity and velocity forces (masses and centres of mass of its bodies)",
                               "its passive forces (damping, stiffness, spring reference)"};
  Culprit c{part, jointName(cx.m, j), cx.joint_action[j] >= 0 ? cx.spec->actNames()[cx.joint_action[j]] : "", Fix::kModel, ""};
  c.advice = "joint '" + c.joint + "' differs from its images in " + what[part_index] + ": the model is not symmetric there";
  return c;
}

}  // namespace

std::string fixName(Fix fix) {
  switch (fix) {
    case Fix::kNone: return "none";
    case Fix::kSign: return "sign";
    case Fix::kPermutation: return "permutation";
    case Fix::kJointAxis: return "joint axis";
    case Fix::kGroupAxis: return "group axis";
    case Fix::kGroupOrder: return "group order";
    case Fix::kModel: return "model";
  }
  return "?";
}

std::string Diagnosis::summary() const {
  std::ostringstream os;
  os << "  parts before the step (joint at T s against the image of its source at s):\n";
  for (const PartCheck& p : parts) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "    %-15s %s worst %.2e", p.name.c_str(), p.worst > tolerance ? "FAIL" : "pass", p.worst);
    os << buf;
    if (p.worst > tolerance) {
      std::vector<NamedError> v = p.joints;
      std::sort(v.begin(), v.end(), [](const NamedError& a, const NamedError& b) { return a.error > b.error; });
      for (int k = 0; k < std::min<int>(4, v.size()) && v[k].error > tolerance; ++k) {
        std::snprintf(buf, sizeof buf, " %s %.2e", v[k].name.c_str(), v[k].error);
        os << buf;
      }
    }
    os << "\n";
  }
  if (culprit)
    os << "  culprit: joint '" << culprit->joint << "'" << (culprit->action.empty() ? "" : " (action " + culprit->action + ")")
       << ", first broken in " << culprit->part << "; likely fix: " << fixName(culprit->fix) << ": " << culprit->advice << "\n";
  return os.str();
}

Diagnosis diagnoseSymmetry(const TaskFactory& factory, const DiagnosisOptions& options) {
  std::unique_ptr<Task> a = factory.create(), b = factory.create(), c = factory.create();
  const sym::SymmetrySpec& spec = a->spec();
  Context cx{a->model(), &spec, a->actionJoints(), std::vector<int>(a->model()->njnt, -1), {}, options.tolerance};
  for (int r = 0; r < static_cast<int>(cx.action_joint.size()); ++r)
    if (cx.action_joint[r] >= 0) {
      cx.joint_action[cx.action_joint[r]] = r;
      cx.bound.push_back(cx.action_joint[r]);
    }
  Diagnosis diag;
  diag.tolerance = options.tolerance;
  for (const char* name : {"kinematics", "actuation", "mass matrix", "bias forces", "passive forces"}) {
    PartCheck p{name, 0.0, {}};
    for (int j = 0; j < cx.m->njnt; ++j) p.joints.push_back({jointName(cx.m, j), 0.0});
    diag.parts.push_back(p);
  }
  Rng rng(options.seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_int_distribution<int> warmup(0, options.max_warmup_steps);
  Eigen::VectorXf act(spec.actDim());
  std::vector<Pair> pairs, broken;
  std::unique_ptr<Task> zeroed = factory.create();
  for (int s = 0; s < options.num_states; ++s) {
    a->reset(rng);
    for (int w = warmup(rng); w > 0; --w) {
      for (int k = 0; k < act.size(); ++k) act(k) = unit(rng);
      const StepOutcome o = a->step(act.data());
      if (o.terminated || o.truncated) a->reset(rng);
    }
    for (int i = 1; i < spec.numAgents(); ++i) {
      zeroed->copyStateFrom(*a);
      zeroJoints(*zeroed);
      checkKinematics(cx, *zeroed, *b, i, diag.parts[0], pairs);
      c->copyStateFrom(*a);
      b->copyStateFrom(*a);
      b->applySymmetry(i);
      for (int k = 0; k < act.size(); ++k) act(k) = unit(rng);
      checkForces(cx, *c, *b, i, act, diag.parts, broken);
    }
  }
  std::vector<Pair> failing;
  for (const Pair& p : pairs)
    if (p.verdict != Verdict::kOk) failing.push_back(p);
  auto any = [&](Verdict v) {
    return std::any_of(failing.begin(), failing.end(), [v](const Pair& p) { return p.verdict == v; });
  };
  if (any(Verdict::kNone)) {
    diag.culprit = groupCulprit(cx, *zeroed, failing);
  } else if (any(Verdict::kPermutation)) {
    diag.culprit = permutationCulprit(cx, pairs);
  } else if (any(Verdict::kSign)) {
    std::vector<Pair> signs;
    for (const Pair& p : failing)
      if (p.verdict == Verdict::kSign) signs.push_back(p);
    diag.culprit = signCulprit(cx, signs);
  } else if (any(Verdict::kAxis)) {
    const int j = mostImplicated(cx, failing);
    diag.culprit = Culprit{"kinematics", jointName(cx.m, j), spec.actNames()[cx.joint_action[j]], Fix::kJointAxis,
                           "joint '" + jointName(cx.m, j) + "''s axis is not the image of its partner's (nor its reverse): " +
                               "the joint axis written in the model is wrong"};
  } else {
    for (int k = 0; k < 4 && !diag.culprit; ++k)
      if (diag.parts[1 + k].worst > options.tolerance) diag.culprit = forceCulprit(cx, broken, k, diag.parts[1 + k].name);
  }
  return diag;
}

}  // namespace masa::task
