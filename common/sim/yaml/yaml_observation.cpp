#include "common/sim/yaml/yaml_observation.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include "common/core/config_error.hpp"
#include "common/symmetry/group_element.hpp"
#include "common/symmetry/kind_action.hpp"

namespace masa::task {
namespace {

constexpr double kSameAction = 1e-9;

// K_i of a spec entry: its kind's action, once per repeat.
Eigen::MatrixXd entryAction(const sym::Entry& e, const sym::Group& g, int i) {
  const int s = sym::entryKindSize(e.kind);
  const Eigen::MatrixXd k = sym::kindAction(e.kind, g, i);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(e.size(), e.size());
  for (int c = 0; c < e.count; ++c) out.block(c * s, c * s, s, s) = k;
  return out;
}

// How a source's values transform under group element i; empty with `why` set when they do not
// transform linearly by themselves.
using NaturalAction = std::function<Eigen::MatrixXd(int i, std::string& why)>;

// The rows and columns `comps` of a 3x3 map, when the map does not mix them with the others.
Eigen::MatrixXd restrict(const Eigen::Matrix3d& a, const std::vector<int>& comps, std::string& why) {
  const int n = static_cast<int>(comps.size());
  Eigen::MatrixXd out(n, n);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const bool rin = std::count(comps.begin(), comps.end(), r) > 0, cin = std::count(comps.begin(), comps.end(), c) > 0;
      if (rin != cin && std::abs(a(r, c)) > kSameAction) {
        why = std::string("the group mixes component ") + char('x' + c) + " into " + char('x' + r) +
              "; observe all three components (or those the group keeps apart)";
        return {};
      }
    }
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) out(r, c) = a(comps[r], comps[c]);
  return out;
}

std::string groupName(const sym::Group& g) {
  const char axis = static_cast<char>('x' + static_cast<int>(g.axis));
  return g.type == sym::GroupType::kReflection ? std::string("the mirror with normal ") + axis
                                               : "the C" + std::to_string(g.order) + " rotation about " + axis;
}

// The spec kinds of one instance of `n` values that act like `natural` (to suggest a fix).
std::string matchingKinds(const NaturalAction& natural, const sym::Group& g, int n) {
  std::string found;
  for (int k = 0; k <= static_cast<int>(sym::EntryKind::kQuaternion); ++k) {
    const auto kind = static_cast<sym::EntryKind>(k);
    if (sym::entryKindSize(kind) != n || !sym::kindUnsupportedReason(kind, g).empty()) continue;
    bool same = true;
    for (int i = 0; i < g.order && same; ++i) {
      std::string why;
      const Eigen::MatrixXd a = natural(i, why);
      same = a.size() > 0 && (a - sym::kindAction(kind, g, i)).cwiseAbs().maxCoeff() < kSameAction;
    }
    if (same) found += (found.empty() ? "'" : " or '") + sym::entryKindName(kind) + "'";
  }
  return found;
}

// `right_kind` names the kind to suggest when the source has one of its own (a joint: its action's).
void checkKind(const ObservationSourceConfig& c, const sym::Entry& e, const sym::SymmetrySpec& spec,
               const std::string& what, const NaturalAction& natural, const std::string& right_kind = "") {
  const sym::Group& g = spec.group();
  for (int i = 0; i < g.order; ++i) {
    std::string why;
    const Eigen::MatrixXd a = natural(i, why);
    if (a.size() == 0)
      throw ConfigError(c.file, c.path, what + " does not transform linearly under " + groupName(g) + ": " + why);
    if (a.rows() == e.size() && (a - entryAction(e, g, i)).cwiseAbs().maxCoeff() < kSameAction) continue;
    const std::string fits = !right_kind.empty() ? "'" + right_kind + "'"
                             : e.count == 1     ? matchingKinds(natural, g, static_cast<int>(a.rows()))
                                                : std::string();
    throw ConfigError(c.file, c.path,
                      what + " transforms under " + groupName(g) + (fits.empty() ? " unlike" : " as kind " + fits + ", not as") +
                          " the kind '" + sym::entryKindName(e.kind) + "' that " + spec.source() + " gives entry '" +
                          e.name + "'");
  }
}

std::string describe(ObsSource s, bool body_frame) {
  switch (s) {
    case ObsSource::kBodyPos: return "a world position";
    case ObsSource::kBodyLinVel: return "a world linear velocity";
    case ObsSource::kBodyAngVel: return body_frame ? "a body-frame angular velocity" : "a world angular velocity";
    case ObsSource::kBodyQuatW: return "the w of an orientation quaternion";
    case ObsSource::kBodyQuatXyz: return "the (x, y, z) of an orientation quaternion";
    case ObsSource::kBodyAxis: return "a body axis in the world";
    case ObsSource::kBodyEuler: return "an Euler angle";
    case ObsSource::kHeading: return "the heading (a world direction)";
    default: return "a joint";
  }
}

// The action entry called `name` in the central or limb block of the action layout, with the
// index of its first action in limb `limb` (or in the central block).
const sym::Entry* actionEntry(const sym::SymmetrySpec& spec, const std::string& name, int limb, int& first) {
  const auto& block = limb < 0 ? spec.actionLayout().central : spec.actionLayout().limb;
  for (const sym::Entry& a : block)
    if (a.name == name) {
      first = (limb < 0 ? 0 : spec.actCentralDim() + limb * spec.actLimbDim()) + a.offset;
      return &a;
    }
  return nullptr;
}

// The action entry an action index belongs to, and its limb (-1: central).
const sym::Entry& entryOfAction(const sym::SymmetrySpec& spec, int action, int& limb) {
  const int cd = spec.actCentralDim();
  limb = action < cd ? -1 : (action - cd) / spec.actLimbDim();
  const int at = action < cd ? action : (action - cd) % spec.actLimbDim();
  const auto& block = limb < 0 ? spec.actionLayout().central : spec.actionLayout().limb;
  for (const sym::Entry& a : block)
    if (at >= a.offset && at < a.offset + a.size()) return a;
  return block.back();  // unreachable: the layout covers every action
}

bool signsMatch(const std::vector<int>& a, const std::vector<int>& b) {
  auto allPlus = [](const std::vector<int>& s) { return std::all_of(s.begin(), s.end(), [](int v) { return v == 1; }); };
  return a == b || (allPlus(a) && allPlus(b));
}

}  // namespace

YamlObservation::YamlObservation(const YamlTaskConfig& config, const Task& task, const std::vector<double>& pose) {
  const sym::SymmetrySpec& spec = task.spec();
  for (const bool limb : {false, true}) {
    const auto& entries = limb ? spec.observationLayout().limb : spec.observationLayout().central;
    const auto& sources = limb ? config.limb : config.central;
    const std::string block = limb ? "limb" : "central";
    std::string names;
    for (const sym::Entry& e : entries) names += (names.empty() ? "" : ", ") + e.name;
    for (const ObservationSourceConfig& c : sources)
      if (std::none_of(entries.begin(), entries.end(), [&](const sym::Entry& e) { return e.name == c.entry; }))
        throw ConfigError(c.file, c.path,
                          spec.source() + " has no " + block + " observation entry '" + c.entry + "' (its " + block +
                              " entries: " + (names.empty() ? "none" : names) + ")");
    for (const sym::Entry& e : entries) {
      const auto it = std::find_if(sources.begin(), sources.end(),
                                   [&](const ObservationSourceConfig& c) { return c.entry == e.name; });
      if (it == sources.end())
        throw ConfigError(config.observation_file, "env.observation." + block + "." + e.name,
                          "missing: " + spec.source() + " has " + block + " observation entry '" + e.name + "' (" +
                              std::to_string(e.size()) + " values of kind " + sym::entryKindName(e.kind) +
                              "); say where it comes from");
      if (!limb) {
        resolve(*it, e, -1, e.offset, task, pose);
      } else {
        for (int k = 0; k < spec.numAgents(); ++k)
          resolve(*it, e, k, spec.obsCentralDim() + k * spec.obsLimbDim() + e.offset, task, pose);
      }
    }
  }
}

// The part of resolution every source shares: the entry's size and, for geometric sources, that
// the entry's kind is how the source transforms under the group.
struct YamlObservation::Resolving {
  const ObservationSourceConfig& c;
  const sym::Entry& e;
  int limb;  // -1: the central block
  const Task& task;
  std::string name;  // the model object this limb's source names ("" when it names none)

  void sizeMustBe(int n, const std::string& what) const {
    if (n != e.size())
      throw ConfigError(c.file, c.path,
                        what + " gives " + std::to_string(n) + " values, but entry '" + e.name + "' of " +
                            task.spec().source() + " holds " + std::to_string(e.size()) + " (kind " +
                            sym::entryKindName(e.kind) + (e.count > 1 ? " x " + std::to_string(e.count) : "") + ")");
  }
  void geometric(const NaturalAction& natural, int n) const {
    sizeMustBe(n, describe(c.source, c.body_frame));
    if (!e.limb_signs.empty() && !signsMatch(e.limb_signs, {}))
      throw ConfigError(c.file, c.path, "entry '" + e.name + "' has limb_signs, which " +
                                            describe(c.source, c.body_frame) + " never needs");
    checkKind(c, e, task.spec(), describe(c.source, c.body_frame) + " ('" + e.name + "')", natural);
  }
};

void YamlObservation::resolve(const ObservationSourceConfig& c, const sym::Entry& e, int limb, int out,
                              const Task& task, const std::vector<double>& pose) {
  Item item;
  item.source = c.source;
  item.out = out;
  item.components = c.components;
  item.axis = c.axis;
  item.body_frame = c.body_frame;
  const Resolving r{c, e, limb, task, c.names.empty() ? "" : c.names[std::max(limb, 0)]};
  switch (c.source) {
    case ObsSource::kJointPos:
    case ObsSource::kJointVel:
    case ObsSource::kLastAction: resolveActuated(r, pose, item); break;
    case ObsSource::kBodyPos:
    case ObsSource::kBodyLinVel:
    case ObsSource::kHeading:
    case ObsSource::kBodyAngVel:
    case ObsSource::kBodyQuatW:
    case ObsSource::kBodyQuatXyz:
    case ObsSource::kBodyAxis:
    case ObsSource::kBodyEuler: resolveBody(r, item); break;
    case ObsSource::kSensor: resolveSensor(r, item); break;
  }
  items_.push_back(std::move(item));
}

// A joint, a joint's velocity or the last action: the joints of an action entry (or one named
// joint), which must be driven by the same limb's actions and change sign as they do.
void YamlObservation::resolveActuated(const Resolving& r, const std::vector<double>& pose, Item& item) {
  const ObservationSourceConfig& c = r.c;
  const sym::Entry& e = r.e;
  const int limb = r.limb;
  const std::string& name = r.name;
  const Task& task = r.task;
  const sym::SymmetrySpec& spec = task.spec();
  const sym::Group& g = spec.group();
  const MujocoModel& model = task.mujocoModel();
  const mjModel* m = model.get();
  const sym::Entry* action = nullptr;
  int first = 0;
  if (c.name_key == "action") {
    action = actionEntry(spec, name, limb, first);
    if (!action) {
      std::string known;
      for (const sym::Entry& a : limb < 0 ? spec.actionLayout().central : spec.actionLayout().limb)
        known += (known.empty() ? "" : ", ") + a.name;
      throw ConfigError(c.file, c.path + ".action",
                        spec.source() + " has no " + (limb < 0 ? "central" : "limb") + " action entry '" + name +
                            "' (" + (known.empty() ? "none" : known) + ")");
    }
    for (int k = 0; k < action->size(); ++k) item.actions.push_back(first + k);
  } else {
    const int j = findNamed(model, mjOBJ_JOINT, name, c.file, c.path + ".joint");
    const auto& joints = task.actionJoints();
    const auto at = std::find(joints.begin(), joints.end(), j);
    if (at == joints.end())
      throw ConfigError(c.file, c.path + ".joint",
                        "joint '" + name + "' is driven by no action of " + spec.source() +
                            ", so the symmetry cannot move it; observe actuated joints only");
    const int a = static_cast<int>(at - joints.begin());
    int action_limb = 0;
    action = &entryOfAction(spec, a, action_limb);
    if (action_limb != limb)
      throw ConfigError(c.file, c.path + ".joint",
                        "joint '" + name + "' is driven by an action of " +
                            (action_limb < 0 ? std::string("the central block") : "limb " + std::to_string(action_limb)) +
                            ", not of " + (limb < 0 ? std::string("the central block") : "limb " + std::to_string(limb)));
    item.actions.push_back(a);
  }
  r.sizeMustBe(static_cast<int>(item.actions.size()), "action entry '" + action->name + "'");
  if (limb >= 0 && !signsMatch(e.limb_signs, action->limb_signs))
    throw ConfigError(c.file, c.path,
                      "entry '" + e.name + "' must carry the limb_signs of action '" + action->name + "' in " +
                          spec.source() + ": its joint changes sign as the action does");
  if (!action->swap_with.empty() || !e.swap_with.empty())
    throw ConfigError(c.file, c.path, "entries with swap_with are not supported by YAML tasks yet");
  sym::Entry one;  // the actions observed: the whole entry, or the one joint named
  one.kind = action->kind;
  one.count = static_cast<int>(item.actions.size()) / sym::entryKindSize(action->kind);
  checkKind(c, e, spec, "the joint of action '" + action->name + "'",
            [&](int i, std::string&) { return entryAction(one, g, i); }, sym::entryKindName(action->kind));
  for (int a : item.actions) {
    const int j = task.actionJoints()[a];
    if (j < 0 || (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE))
      throw ConfigError(c.file, c.path, "action " + spec.actNames()[a] + " drives no hinge or slide joint");
    item.qadr.push_back(m->jnt_qposadr[j]);
    item.dofadr.push_back(m->jnt_dofadr[j]);
    // The pose is checked symmetric (yaml_task.cpp), so the offset keeps the joint's kind.
    item.joint_offset.push_back(c.from_pose ? pose[a] : 0.0);
  }
}

// A body's position, velocities, orientation or axes, or the heading: the components the config
// picks, each checked to transform as the entry's kind says.
void YamlObservation::resolveBody(const Resolving& r, Item& item) {
  const ObservationSourceConfig& c = r.c;
  const std::string& name = r.name;
  const sym::SymmetrySpec& spec = r.task.spec();
  const sym::Group& g = spec.group();
  const MujocoModel& model = r.task.mujocoModel();
  const int n_comp = static_cast<int>(c.components.size());
  auto geometric = [&r](const NaturalAction& natural, int n) { r.geometric(natural, n); };
  switch (c.source) {
    case ObsSource::kBodyPos:
    case ObsSource::kBodyLinVel:
    case ObsSource::kHeading:
      if (c.source == ObsSource::kBodyPos) item.body = findNamed(model, mjOBJ_BODY, name, c.file, c.path + ".body");
      if (!c.above_geom.empty()) {
        item.height_offset = worldGeomTop(model, c.above_geom, c.file, c.path + ".above_geom");
        // A constant offset stays linear only on a component the group leaves alone.
        for (int i = 0; i < g.order; ++i)
          if (std::abs(sym::spatialMap(g, i)(2, 2) - 1.0) > kSameAction)
            throw ConfigError(c.file, c.path + ".above_geom",
                              "a height above a geom is not kept by " + groupName(g) + ": the group moves z");
      }
      if (c.source == ObsSource::kBodyLinVel) item.free = findFreeBody(model, spec, name, c.file, c.path + ".body");
      geometric([&](int i, std::string& why) { return restrict(sym::spatialMap(g, i), c.components, why); }, n_comp);
      break;
    case ObsSource::kBodyAngVel:
      item.free = findFreeBody(model, spec, name, c.file, c.path + ".body");
      geometric(
          [&](int i, std::string& why) {
            Eigen::Matrix3d lin, ang;
            freeJointVelocityBlocks(g, i, item.free.kind, lin, ang);
            const Eigen::Matrix3d s = sym::spatialMap(g, i);
            return restrict(c.body_frame ? ang : Eigen::Matrix3d(s.determinant() * s), c.components, why);
          },
          n_comp);
      break;
    case ObsSource::kBodyQuatW:
    case ObsSource::kBodyQuatXyz: {
      item.free = findFreeBody(model, spec, name, c.file, c.path + ".body");
      const bool w = c.source == ObsSource::kBodyQuatW;
      geometric(
          [&](int i, std::string& why) -> Eigen::MatrixXd {
            const Eigen::Matrix3d s = sym::spatialMap(g, i);
            if (item.free.kind == sym::FreeJointKind::kObject && !sym::isMirror(g, i) && i != 0) {
              why = "a carried object's orientation is rotated (g R), which mixes w with (x, y, z); observe a body "
                    "axis (source: body_axis) instead";
              return {};
            }
            // A robot base's orientation is conjugated (g R g^-1): w keeps, (x, y, z) is an axial vector.
            if (w) return Eigen::MatrixXd::Identity(1, 1);
            return Eigen::MatrixXd(s.determinant() * s);
          },
          w ? 1 : 3);
      break;
    }
    case ObsSource::kBodyAxis:
      item.free = findFreeBody(model, spec, name, c.file, c.path + ".body");
      geometric(
          [&](int i, std::string& why) -> Eigen::MatrixXd {
            const Eigen::Matrix3d s = sym::spatialMap(g, i);
            if (item.free.kind == sym::FreeJointKind::kObject && !sym::isMirror(g, i)) return s;  // g R e
            // g R g^-1 e (a mirror: M R M e) is linear in R e only when g^-1 e = +-e.
            const Eigen::Vector3d e_local = Eigen::Vector3d::Unit(c.axis);
            const Eigen::Vector3d back = s.transpose() * e_local;
            if ((back - e_local).norm() < kSameAction) return s;
            if ((back + e_local).norm() < kSameAction) return Eigen::Matrix3d(-s);
            why = std::string("the body's local ") + char('x' + c.axis) +
                  " axis is moved to another axis by the group; observe the axis along the symmetry axis (or normal)";
            return {};
          },
          3);
      break;
    case ObsSource::kBodyEuler:
      item.free = findFreeBody(model, spec, name, c.file, c.path + ".body");
      geometric(
          [&](int i, std::string& why) -> Eigen::MatrixXd {
            if (g.type != sym::GroupType::kReflection) {
              why = "a rotation of the world shifts the yaw by a constant and mixes roll with pitch; observe the "
                    "quaternion (body_quat_w + body_quat_xyz) or body axes";
              return {};
            }
            // Under the mirror M R M, the angle about the normal keeps its sign and the other two flip.
            const bool keeps = i == 0 || c.axis == static_cast<int>(g.axis);
            return Eigen::MatrixXd::Constant(1, 1, keeps ? 1.0 : -1.0);
          },
          1);
      break;
    default:  // the other sources are resolveActuated's and resolveSensor's
      break;
  }
}

// A sensor, taken at the spec's word (the physics verifier checks it).
void YamlObservation::resolveSensor(const Resolving& r, Item& item) {
  const ObservationSourceConfig& c = r.c;
  const std::string& name = r.name;
  const mjModel* m = r.task.mujocoModel().get();
  const int s = findNamed(r.task.mujocoModel(), mjOBJ_SENSOR, name, c.file, c.path + ".sensor");
  item.sensor_adr = m->sensor_adr[s];
  item.sensor_dim = m->sensor_dim[s];
  r.sizeMustBe(item.sensor_dim, "sensor '" + name + "'");
  uses_sensors_ = true;
}

void YamlObservation::write(const mjData* d, const std::vector<double>& last_action, const Eigen::Vector3d& heading,
                            float* out) const {
  auto putComponents = [](const Eigen::Vector3d& v, const std::vector<int>& comps, float* o) {
    for (std::size_t k = 0; k < comps.size(); ++k) o[k] = static_cast<float>(v[comps[k]]);
  };
  for (const Item& it : items_) {
    float* o = out + it.out;
    switch (it.source) {
      case ObsSource::kJointPos:
        for (std::size_t k = 0; k < it.qadr.size(); ++k) o[k] = static_cast<float>(d->qpos[it.qadr[k]] - it.joint_offset[k]);
        break;
      case ObsSource::kJointVel:
        for (std::size_t k = 0; k < it.dofadr.size(); ++k) o[k] = static_cast<float>(d->qvel[it.dofadr[k]]);
        break;
      case ObsSource::kLastAction:
        for (std::size_t k = 0; k < it.actions.size(); ++k) o[k] = static_cast<float>(last_action[it.actions[k]]);
        break;
      case ObsSource::kBodyPos: {
        Eigen::Vector3d p(d->xpos + 3 * it.body);
        p.z() -= it.height_offset;
        putComponents(p, it.components, o);
        break;
      }
      case ObsSource::kBodyLinVel: putComponents(it.free.linearVelocity(d), it.components, o); break;
      case ObsSource::kBodyAngVel:
        putComponents(it.body_frame ? it.free.angularVelocityBody(d) : it.free.angularVelocityWorld(d), it.components, o);
        break;
      case ObsSource::kBodyQuatW:
      case ObsSource::kBodyQuatXyz: {
        // q and -q are one orientation; w >= 0 picks one, and conjugation keeps w, so the choice is equivariant.
        const double* q = d->xquat + 4 * it.free.body;
        const double s = q[0] < 0 ? -1.0 : 1.0;
        if (it.source == ObsSource::kBodyQuatW)
          o[0] = static_cast<float>(s * q[0]);
        else
          for (int k = 0; k < 3; ++k) o[k] = static_cast<float>(s * q[1 + k]);
        break;
      }
      case ObsSource::kBodyAxis: putComponents(it.free.axisInWorld(d, it.axis), {0, 1, 2}, o); break;
      case ObsSource::kBodyEuler: {
        const double* r = d->xmat + 9 * it.free.body;
        const double angle = it.axis == 0   ? std::atan2(r[7], r[8])
                             : it.axis == 1 ? std::asin(std::clamp(-r[6], -1.0, 1.0))
                                            : std::atan2(r[3], r[0]);
        o[0] = static_cast<float>(angle);
        break;
      }
      case ObsSource::kHeading: putComponents(heading, it.components, o); break;
      case ObsSource::kSensor:
        for (int k = 0; k < it.sensor_dim; ++k) o[k] = static_cast<float>(d->sensordata[it.sensor_adr + k]);
        break;
    }
  }
}

}  // namespace masa::task
