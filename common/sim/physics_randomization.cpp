#include "common/sim/physics_randomization.hpp"

#include <cmath>
#include <algorithm>
#include <numeric>
#include <random>
#include <stdexcept>

#include "common/core/config_error.hpp"
#include "common/sim/com_offsets.hpp"
#include "common/symmetry/group_element.hpp"

namespace masa::task {
namespace {

// A scale range: [lo, hi] (a list of two) or one number (fixed), finite, 0 < lo <= hi.
ScaleRange readScale(EnvParams& params, const std::string& key) {
  const YAML::Node n = params.section(key);
  ScaleRange r;
  if (!n.IsDefined() || n.IsNull()) return r;
  auto bad = [&](const std::string& why) { return ConfigError(params.origin(key), "env." + key, why); };
  try {
    if (n.IsSequence()) {
      if (n.size() != 2) throw bad("expected [min, max], got " + std::to_string(n.size()) + " values");
      r.lo = n[0].as<double>();
      r.hi = n[1].as<double>();
    } else {
      r.lo = r.hi = n.as<double>();
    }
  } catch (const YAML::Exception&) {
    throw bad("expected a number or [min, max], got '" + YAML::Dump(n) + "'");
  }
  if (!std::isfinite(r.lo) || !std::isfinite(r.hi)) throw bad("expected finite numbers, got '" + YAML::Dump(n) + "'");
  if (!(r.lo > 0.0)) throw bad("a scale must be positive, got " + std::to_string(r.lo));
  if (r.lo > r.hi) throw bad("min " + std::to_string(r.lo) + " is above max " + std::to_string(r.hi));
  return r;
}

// Union-find over element indices: the orbits of the symmetry's permutations.
struct Orbits {
  std::vector<int> parent;
  explicit Orbits(int n) : parent(static_cast<std::size_t>(n)) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) { return parent[x] == x ? x : parent[x] = find(parent[x]); }
  void join(int a, int b) { parent[find(a)] = find(b); }
  // Dense group ids 0..k-1, in element order; returns k.
  int groups(std::vector<int>& out) {
    out.assign(parent.size(), -1);
    std::vector<int> id(parent.size(), -1);
    int k = 0;
    for (std::size_t e = 0; e < parent.size(); ++e) {
      const int root = find(static_cast<int>(e));
      if (id[root] < 0) id[root] = k++;
      out[e] = id[root];
    }
    return k;
  }
};

// Every group of one element joins one "rest" group (the last id); ids stay dense. Returns the
// number of groups, and the rest group's id in *rest (-1: every group had several elements).
int mergeSingletons(std::vector<int>& group, int* rest) {
  std::vector<int> size;
  for (int g : group) {
    if (g >= static_cast<int>(size.size())) size.resize(static_cast<std::size_t>(g) + 1, 0);
    ++size[g];
  }
  std::vector<int> id(size.size(), -1);
  int next = 0;
  for (std::size_t g = 0; g < size.size(); ++g)
    if (size[g] > 1) id[g] = next++;
  *rest = -1;
  for (int& g : group) {
    if (id[g] < 0) {
      if (*rest < 0) *rest = next;
      g = *rest;
    } else {
      g = id[g];
    }
  }
  return next + (*rest >= 0 ? 1 : 0);
}

}  // namespace

RandomizationConfig RandomizationConfig::read(EnvParams& params) {
  RandomizationConfig c;
  const YAML::Node section = params.section("randomization");
  if (!section.IsDefined() || section.IsNull()) return c;
  if (!section.IsMap()) throw ConfigError(params.origin("randomization"), "env.randomization", "expected a mapping");
  static const std::vector<std::string> known = {"per_limb",       "mass_scale",    "geom_friction_scale",
                                                 "joint_damping_scale", "joint_friction_scale", "actuator_strength",
                                                 "latency_steps",  "obs_noise_std", "obs_bias",
                                                 "pd_kp_scale",    "pd_kd_scale",   "push_velocity", "push_interval_s",
                                                 "com_offset"};
  for (const auto& kv : section) {
    const std::string key = kv.first.as<std::string>();
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw ConfigError(params.origin("randomization." + key), "env.randomization." + key,
                        "unknown randomization key (known: " + list + ")");
    }
  }
  c.enabled = true;
  c.per_limb = params.flag("randomization.per_limb", false);
  c.mass = readScale(params, "randomization.mass_scale");
  c.geom_friction = readScale(params, "randomization.geom_friction_scale");
  c.joint_damping = readScale(params, "randomization.joint_damping_scale");
  c.joint_friction = readScale(params, "randomization.joint_friction_scale");
  c.actuator_strength = readScale(params, "randomization.actuator_strength");
  c.pd_kp = readScale(params, "randomization.pd_kp_scale");
  c.pd_kd = readScale(params, "randomization.pd_kd_scale");
  // Latency: [min, max] steps, 0 allowed (a scale range read, then checked for >= 0 instead).
  const YAML::Node lat = params.section("randomization.latency_steps");
  if (lat.IsDefined() && !lat.IsNull()) {
    const std::string key = "randomization.latency_steps";
    auto bad = [&](const std::string& why) { return ConfigError(params.origin(key), "env." + key, why); };
    try {
      if (lat.IsSequence() && lat.size() == 2) {
        c.latency_lo = lat[0].as<double>();
        c.latency_hi = lat[1].as<double>();
      } else if (!lat.IsSequence()) {
        c.latency_lo = c.latency_hi = lat.as<double>();
      } else {
        throw bad("expected [min, max] control steps");
      }
    } catch (const YAML::Exception&) {
      throw bad("expected a number or [min, max], got '" + YAML::Dump(lat) + "'");
    }
    if (!std::isfinite(c.latency_lo) || !std::isfinite(c.latency_hi)) throw bad("expected finite numbers");
    if (c.latency_lo < 0.0) throw bad("a latency cannot be negative, got " + std::to_string(c.latency_lo));
    if (c.latency_lo > c.latency_hi) throw bad("min " + std::to_string(c.latency_lo) + " is above max " + std::to_string(c.latency_hi));
    if (c.latency_hi > 100.0) throw bad("at most 100 control steps, got " + std::to_string(c.latency_hi));
  }
  c.obs_noise_std = params.number("randomization.obs_noise_std", 0.0);
  c.obs_bias = params.number("randomization.obs_bias", 0.0);
  if (c.obs_noise_std < 0.0)
    throw ConfigError(params.origin("randomization.obs_noise_std"), "env.randomization.obs_noise_std",
                      "cannot be negative, got " + std::to_string(c.obs_noise_std));
  if (c.obs_bias < 0.0)
    throw ConfigError(params.origin("randomization.obs_bias"), "env.randomization.obs_bias",
                      "cannot be negative, got " + std::to_string(c.obs_bias));
  c.com_offset = params.number("randomization.com_offset", 0.0);
  if (!(c.com_offset >= 0.0) || !std::isfinite(c.com_offset))
    throw ConfigError(params.origin("randomization.com_offset"), "env.randomization.com_offset",
                      "expected a finite distance >= 0 (metres), got " + std::to_string(c.com_offset));
  c.push_velocity = params.number("randomization.push_velocity", 0.0);
  c.push_interval_s = params.number("randomization.push_interval_s", 0.0);
  if (!(c.push_velocity >= 0.0) || !std::isfinite(c.push_velocity))
    throw ConfigError(params.origin("randomization.push_velocity"), "env.randomization.push_velocity",
                      "expected a finite speed >= 0 (m/s), got " + std::to_string(c.push_velocity));
  if (c.push_velocity > 0.0 && !(c.push_interval_s > 0.0 && std::isfinite(c.push_interval_s)))
    throw ConfigError(params.origin("randomization.push_interval_s"), "env.randomization.push_interval_s",
                      "pushes need a finite mean interval > 0 (seconds), got " + std::to_string(c.push_interval_s));
  return c;
}

PhysicsRandomization::PhysicsRandomization(const RandomizationConfig& config, mjModel* model,
                                           const sym::SymmetrySpec& spec, const std::vector<int>& action_joint,
                                           const std::vector<int>& action_actuator)
    : config_(config), m_(model), obs_dim_(spec.obsDim()) {
  const mjModel* m = m_;
  mass0_.assign(m->body_mass, m->body_mass + m->nbody);
  inertia0_.assign(m->body_inertia, m->body_inertia + 3 * m->nbody);
  friction0_.assign(m->geom_friction, m->geom_friction + 3 * m->ngeom);
  damping0_.assign(m->dof_damping, m->dof_damping + m->nv);
  frictionloss0_.assign(m->dof_frictionloss, m->dof_frictionloss + m->nv);
  gear0_.assign(m->actuator_gear, m->actuator_gear + 6 * m->nu);
  ipos0_.assign(m->body_ipos, m->body_ipos + 3 * m->nbody);

  // The orbits: action r and the action T_i maps onto it drive joints (and actuators) the symmetry
  // carries onto each other, for every group element; their bodies, those bodies' geoms (in
  // order) and the joints' dofs follow. Everything else is its own orbit (mapped onto itself).
  Orbits joints(m->njnt), actuators(m->nu), bodies(m->nbody);
  if (!config.per_limb) {
    for (int i = 1; i < spec.numAgents(); ++i) {
      const sym::SparseMap& t = spec.actTransform(i);
      for (int r = 0; r < t.rows(); ++r)
        for (int p = t.rowStart()[r]; p < t.rowStart()[r + 1]; ++p) {
          const int c = t.colIndex()[p];
          if (action_joint[r] >= 0 && action_joint[c] >= 0) {
            joints.join(action_joint[r], action_joint[c]);
            bodies.join(m->jnt_bodyid[action_joint[r]], m->jnt_bodyid[action_joint[c]]);
          }
          if (action_actuator[r] >= 0 && action_actuator[c] >= 0) actuators.join(action_actuator[r], action_actuator[c]);
        }
    }
  }
  std::vector<int> joint_group;
  n_dof_groups_ = joints.groups(joint_group);
  n_body_groups_ = bodies.groups(body_orbit_);
  n_actuator_groups_ = actuators.groups(actuator_orbit_);
  int rest_body = -1;
  if (!config.per_limb) {
    // What no permutation reaches (the trunk, welded feet, an arena's walls, a cube) may still be
    // images of each other: one draw for all of it keeps the symmetry whatever it is.
    int rest = -1;
    n_dof_groups_ = mergeSingletons(joint_group, &rest);
    n_actuator_groups_ = mergeSingletons(actuator_orbit_, &rest);
    n_body_groups_ = mergeSingletons(body_orbit_, &rest_body);
  }
  // A geom's group: its body's orbit and its index among the body's geoms (bodies of one orbit
  // with different geom counts: one group per geom); the rest's geoms share one group.
  geom_orbit_.assign(static_cast<std::size_t>(m->ngeom), -1);
  int rest_geom = -1;
  std::vector<std::vector<int>> orbit_bodies(static_cast<std::size_t>(n_body_groups_));
  for (int b = 0; b < m->nbody; ++b) orbit_bodies[body_orbit_[b]].push_back(b);
  for (int group = 0; group < n_body_groups_; ++group) {
    const auto& members = orbit_bodies[group];
    bool same = !config.per_limb;
    for (int b : members) same = same && m->body_geomnum[b] == m->body_geomnum[members[0]];
    for (int b : members)
      for (int k = 0; k < m->body_geomnum[b]; ++k) {
        const int g = m->body_geomadr[b] + k;
        if (!config.per_limb && group == rest_body) {
          if (rest_geom < 0) rest_geom = n_geom_groups_++;
          geom_orbit_[g] = rest_geom;
        } else if (same) {
          const int first = m->body_geomadr[members[0]] + k;
          geom_orbit_[g] = geom_orbit_[first] >= 0 ? geom_orbit_[first] : n_geom_groups_++;
        } else {
          geom_orbit_[g] = n_geom_groups_++;
        }
      }
  }
  dof_orbit_.assign(static_cast<std::size_t>(m->nv), -1);
  for (int v = 0; v < m->nv; ++v) dof_orbit_[v] = joint_group[m->dof_jntid[v]];
  // An action's PD gains follow its joint's orbit (an action without a joint: the first group).
  action_group_.clear();
  for (int j : action_joint) action_group_.push_back(j >= 0 ? joint_group[j] : 0);

  body_scale_.assign(static_cast<std::size_t>(n_body_groups_), 1.0);
  geom_scale_.assign(static_cast<std::size_t>(n_geom_groups_), 1.0);
  damping_scale_.assign(static_cast<std::size_t>(n_dof_groups_), 1.0);
  frictionloss_scale_.assign(static_cast<std::size_t>(n_dof_groups_), 1.0);
  actuator_scale_.assign(static_cast<std::size_t>(n_actuator_groups_), 1.0);
  kp_scale_.assign(static_cast<std::size_t>(std::max(n_dof_groups_, 1)), 1.0);
  kd_scale_.assign(static_cast<std::size_t>(std::max(n_dof_groups_, 1)), 1.0);
  obs_bias_.assign(static_cast<std::size_t>(obs_dim_), 0.0);
  scratch_ = mj_makeData(m_);

  // For the centre-of-mass offsets: where T_i carries each body (the action map: the joint of
  // column c moves to that of row r), the spatial maps S_i, the robot base, and each body's
  // orientation at the reference pose (the offsets are drawn in the world frame there).
  body_image_.assign(static_cast<std::size_t>(spec.numAgents()), std::vector<int>(static_cast<std::size_t>(m->nbody), -1));
  for (int i = 0; i < spec.numAgents(); ++i) {
    const sym::SparseMap& t = spec.actTransform(i);
    for (int r = 0; r < t.rows(); ++r)
      for (int p = t.rowStart()[r]; p < t.rowStart()[r + 1]; ++p) {
        const int c = t.colIndex()[p];
        if (action_joint[r] >= 0 && action_joint[c] >= 0)
          body_image_[i][m->jnt_bodyid[action_joint[c]]] = m->jnt_bodyid[action_joint[r]];
      }
    const Eigen::Matrix3d s = sym::spatialMap(spec.group(), i);
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col) spatial_map_.push_back(s(row, col));
  }
  for (const auto& fj : spec.mujoco().free_joints)
    if (fj.kind == sym::FreeJointKind::kRobotBase) {
      const int j = mj_name2id(m, mjOBJ_JOINT, fj.name.c_str());
      if (j >= 0) base_body_ = m->jnt_bodyid[j];
    }
  mj_resetData(m, scratch_);
  mj_kinematics(m, scratch_);
  body_rot0_.assign(scratch_->xmat, scratch_->xmat + 9 * m->nbody);
  com_offset_.assign(3 * static_cast<std::size_t>(m->nbody), 0.0);
}

void PhysicsRandomization::drawEpisode(Rng& rng) {
  auto draw = [&](const ScaleRange& r, std::vector<double>& scales) {
    if (!r.active()) return;
    std::uniform_real_distribution<double> u(r.lo, r.hi);
    for (double& s : scales) s = u(rng);
  };
  draw(config_.mass, body_scale_);
  draw(config_.geom_friction, geom_scale_);
  draw(config_.joint_damping, damping_scale_);
  draw(config_.joint_friction, frictionloss_scale_);
  draw(config_.actuator_strength, actuator_scale_);
  draw(config_.pd_kp, kp_scale_);
  draw(config_.pd_kd, kd_scale_);
  if (config_.com_offset > 0.0) drawComOffsets(config_.com_offset, config_.per_limb, body_image_, spatial_map_, base_body_, rng, com_offset_);
  if (config_.latency_hi > 0.0) latency_ = std::uniform_real_distribution<double>(config_.latency_lo, config_.latency_hi)(rng);
  if (config_.obs_bias > 0.0) {
    std::uniform_real_distribution<double> u(-config_.obs_bias, config_.obs_bias);
    for (double& b : obs_bias_) b = u(rng);
  }
  apply();
}

void PhysicsRandomization::apply() {
  mjModel* m = m_;
  for (int b = 0; b < m->nbody; ++b) {
    const double s = body_scale_[body_orbit_[b]];
    m->body_mass[b] = mass0_[b] * s;
    for (int k = 0; k < 3; ++k) m->body_inertia[3 * b + k] = inertia0_[3 * b + k] * s;
  }
  for (int g = 0; g < m->ngeom; ++g)
    for (int k = 0; k < 3; ++k) m->geom_friction[3 * g + k] = friction0_[3 * g + k] * geom_scale_[geom_orbit_[g]];
  for (int v = 0; v < m->nv; ++v) {
    m->dof_damping[v] = damping0_[v] * damping_scale_[dof_orbit_[v]];
    m->dof_frictionloss[v] = frictionloss0_[v] * frictionloss_scale_[dof_orbit_[v]];
  }
  for (int a = 0; a < m->nu; ++a)
    for (int k = 0; k < 6; ++k) m->actuator_gear[6 * a + k] = gear0_[6 * a + k] * actuator_scale_[actuator_orbit_[a]];
  // The offset is drawn in the world frame at the reference pose: into each body's own frame (R^T d).
  for (int b = 0; b < m->nbody; ++b)
    for (int k = 0; k < 3; ++k) {
      const double* rot = body_rot0_.data() + 9 * b;
      const double* d = com_offset_.data() + 3 * b;
      m->body_ipos[3 * b + k] = ipos0_[3 * b + k] + rot[k] * d[0] + rot[3 + k] * d[1] + rot[6 + k] * d[2];
    }
  latency_steps_ = static_cast<int>(std::floor(latency_));
  // The derived quantities (body_subtreemass, the inverse weights at qpos0, ...) from the new masses.
  mj_setConst(m, scratch_);
}

PhysicsRandomization::~PhysicsRandomization() {
  if (scratch_) mj_deleteData(scratch_);
}

void PhysicsRandomization::save(std::vector<double>& out) const {
  for (const auto* v : {&body_scale_, &geom_scale_, &damping_scale_, &frictionloss_scale_, &actuator_scale_, &kp_scale_,
                        &kd_scale_, &obs_bias_, &com_offset_})
    out.insert(out.end(), v->begin(), v->end());
  out.push_back(latency_);
}

std::size_t PhysicsRandomization::load(std::span<const double> in, const std::string& task_name) {
  std::size_t at = 0;
  for (auto* v : {&body_scale_, &geom_scale_, &damping_scale_, &frictionloss_scale_, &actuator_scale_, &kp_scale_,
                  &kd_scale_, &obs_bias_, &com_offset_}) {
    if (in.size() < at + v->size()) throw std::runtime_error("task state of " + task_name + ": the randomized physics is cut short");
    std::copy(in.begin() + static_cast<std::ptrdiff_t>(at), in.begin() + static_cast<std::ptrdiff_t>(at + v->size()), v->begin());
    at += v->size();
  }
  if (in.size() < at + 1) throw std::runtime_error("task state of " + task_name + ": the randomized physics is cut short");
  latency_ = in[at++];
  for (const auto* v : {&body_scale_, &geom_scale_, &damping_scale_, &frictionloss_scale_, &actuator_scale_, &kp_scale_,
                        &kd_scale_})
    for (double x : *v)
      if (!(x > 0.0) || !std::isfinite(x)) throw std::runtime_error("task state of " + task_name + ": a randomized scale is not positive");
  if (!(latency_ >= 0.0 && latency_ <= 100.0)) throw std::runtime_error("task state of " + task_name + ": a bad latency");
  apply();
  return at;
}

const std::vector<std::string>& PhysicsRandomization::drawNames() {
  static const std::vector<std::string> names = {
      "physics: mass_scale",        "physics: geom_friction_scale", "physics: joint_damping_scale",
      "physics: joint_friction_scale", "physics: actuator_strength", "physics: pd_kp_scale",
      "physics: pd_kd_scale",       "physics: latency_steps"};
  return names;
}

void PhysicsRandomization::summarize(std::vector<double>& out) const {
  out.clear();
  auto mean = [](const std::vector<double>& v) {
    double sum = 0;
    for (double x : v) sum += x;
    return v.empty() ? 1.0 : sum / static_cast<double>(v.size());
  };
  for (const auto* v : {&body_scale_, &geom_scale_, &damping_scale_, &frictionloss_scale_, &actuator_scale_, &kp_scale_,
                        &kd_scale_})
    out.push_back(mean(*v));
  out.push_back(latency_);
}

void PhysicsRandomization::perturbObservation(float* obs, int n, Rng& noise_rng) const {
  if (config_.obs_noise_std > 0.0) {
    std::normal_distribution<double> noise(0.0, config_.obs_noise_std);
    for (int k = 0; k < n; ++k) obs[k] = static_cast<float>(obs[k] + obs_bias_[k] + noise(noise_rng));
  } else if (config_.obs_bias > 0.0) {
    for (int k = 0; k < n; ++k) obs[k] = static_cast<float>(obs[k] + obs_bias_[k]);
  }
}

}  // namespace masa::task
