#include "common/sim/model_lookup.hpp"

#include "common/core/config_error.hpp"

namespace masa::task {

int findNamed(const MujocoModel& model, int type, const std::string& name, const std::string& file,
              const std::string& path) {
  const mjModel* m = model.get();
  const int id = mj_name2id(m, type, name.c_str());
  if (id >= 0) return id;
  const char* type_name = mju_type2Str(type);
  std::string known;
  int count = 0;
  const int total = type == mjOBJ_BODY     ? m->nbody
                    : type == mjOBJ_JOINT  ? m->njnt
                    : type == mjOBJ_SENSOR ? m->nsensor
                    : type == mjOBJ_GEOM   ? m->ngeom
                                           : 0;
  for (int k = 0; k < total; ++k)
    if (const char* n = mj_id2name(m, type, k); n && *n) known += (count++ ? ", " : "") + std::string(n);
  throw ConfigError(file, path,
                    model.path() + " has no " + (type_name ? type_name : "object") + " named '" + name + "'" +
                        (count ? " (it has: " + known + ")" : " (it names none)"));
}

double worldGeomTop(const MujocoModel& model, const std::string& name, const std::string& file,
                    const std::string& path) {
  const mjModel* m = model.get();
  const int g = findNamed(model, mjOBJ_GEOM, name, file, path);
  if (m->geom_bodyid[g] != 0)
    throw ConfigError(file, path, "geom '" + name + "' must be fixed in the world (a child of worldbody)");
  const double* q = m->geom_quat + 4 * g;
  if (q[1] != 0.0 || q[2] != 0.0)
    throw ConfigError(file, path, "geom '" + name + "' is tilted: its top is not one height");
  const double* size = m->geom_size + 3 * g;
  const double z = m->geom_pos[3 * g + 2];
  switch (m->geom_type[g]) {
    case mjGEOM_PLANE: return z;
    case mjGEOM_BOX: return z + size[2];
    case mjGEOM_SPHERE: return z + size[0];
    case mjGEOM_CYLINDER: return z + size[1];
    case mjGEOM_CAPSULE: return z + size[0] + size[1];
    default: throw ConfigError(file, path, "geom '" + name + "': its top is known for a plane, box, sphere, cylinder "
                                           "or capsule only");
  }
}

FreeBody findFreeBody(const MujocoModel& model, const sym::SymmetrySpec& spec, const std::string& name,
                      const std::string& file, const std::string& path) {
  const mjModel* m = model.get();
  FreeBody f;
  f.body = findNamed(model, mjOBJ_BODY, name, file, path);
  int joint = -1;
  for (int j = 0; j < m->njnt; ++j)
    if (m->jnt_bodyid[j] == f.body && m->jnt_type[j] == mjJNT_FREE) joint = j;
  if (joint < 0)
    throw ConfigError(file, path,
                      "body '" + name + "' has no free joint, so its velocity and orientation are not in the state; "
                      "observe it with a MuJoCo sensor (source: sensor) instead");
  const char* jn = mj_id2name(m, mjOBJ_JOINT, joint);
  bool listed = false;
  for (const auto& fj : spec.mujoco().free_joints)
    if (jn && fj.name == jn) {
      listed = true;
      f.kind = fj.kind;
    }
  if (!listed)
    throw ConfigError(file, path,
                      "the free joint '" + std::string(jn ? jn : "(unnamed)") + "' of body '" + name + "' is not in " +
                          spec.source() + "'s mujoco.free_joints (say there whether it is the robot_base or an object)");
  f.qadr = m->jnt_qposadr[joint];
  f.vadr = m->jnt_dofadr[joint];
  return f;
}

Eigen::Vector3d FreeBody::linearVelocity(const mjData* d) const { return Eigen::Vector3d(d->qvel + vadr); }

Eigen::Vector3d FreeBody::angularVelocityBody(const mjData* d) const { return Eigen::Vector3d(d->qvel + vadr + 3); }

Eigen::Vector3d FreeBody::angularVelocityWorld(const mjData* d) const {
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> r(d->xmat + 9 * body);
  return r * angularVelocityBody(d);
}

Eigen::Vector3d FreeBody::axisInWorld(const mjData* d, int local_axis) const {
  const double* r = d->xmat + 9 * body;
  return Eigen::Vector3d(r[local_axis], r[3 + local_axis], r[6 + local_axis]);
}

}  // namespace masa::task
