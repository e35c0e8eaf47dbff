#include "common/physics_symmetry/imperfection_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>

namespace masa::task {

ImperfectionReport imperfectionReport(const TaskFactory& factory, const SymmetryVerifierOptions& options) {
  ImperfectionReport report;
  std::unique_ptr<Task> t = factory.create();
  if (t->randomization()) {
    // env.randomization: the model of an episode drawn from the seed (per_limb: limbs that differ).
    Rng rng(options.seed);
    t->reset(rng);
  }
  const mjModel* m = t->model();
  const sym::SymmetrySpec& spec = t->spec();
  const int n = spec.numAgents(), cd = spec.actCentralDim(), ld = spec.actLimbDim();
  auto actuator = [&](int j) {
    for (int a = 0; a < m->nu; ++a)
      if (m->actuator_trntype[a] == mjTRN_JOINT && m->actuator_trnid[2 * a] == j) return a;
    return -1;
  };
  auto width = [](const mjtNum* r) { return r[1] - r[0]; };
  using Term = std::pair<const char*, std::function<double(int)>>;  // value for a joint
  const std::vector<Term> terms = {
      {"mass", [&](int j) { return m->body_mass[m->jnt_bodyid[j]]; }},
      {"inertia", [&](int j) { const mjtNum* i = m->body_inertia + 3 * m->jnt_bodyid[j]; return i[0] + i[1] + i[2]; }},
      {"com offset", [&](int j) { const mjtNum* p = m->body_ipos + 3 * m->jnt_bodyid[j]; return std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]); }},
      {"damping", [&](int j) { return m->dof_damping[m->jnt_dofadr[j]]; }},
      {"armature", [&](int j) { return m->dof_armature[m->jnt_dofadr[j]]; }},
      {"friction loss", [&](int j) { return m->dof_frictionloss[m->jnt_dofadr[j]]; }},
      {"stiffness", [&](int j) { return m->jnt_stiffness[j]; }},
      {"range", [&](int j) { return m->jnt_limited[j] ? width(m->jnt_range + 2 * j) : 0.0; }},
      {"gear", [&](int j) { const int a = actuator(j); return a < 0 ? 0.0 : std::abs(m->actuator_gear[6 * a]); }},
      {"ctrlrange", [&](int j) { const int a = actuator(j); return a < 0 || !m->actuator_ctrllimited[a] ? 0.0 : width(m->actuator_ctrlrange + 2 * a); }},
  };
  for (int s = 0; s < ld; ++s) {
    for (const auto& [name, value] : terms) {
      std::vector<double> v(n);
      std::vector<int> joints(n);
      for (int k = 0; k < n; ++k) {
        joints[k] = t->actionJoints()[cd + k * ld + s];
        v[k] = joints[k] >= 0 ? value(joints[k]) : 0.0;
      }
      // Against the median: the one limb that differs stands alone (the mean would move the others).
      std::vector<double> sorted = v;
      std::sort(sorted.begin(), sorted.end());
      const double mean = 0.5 * (sorted[(n - 1) / 2] + sorted[n / 2]);
      for (int k = 0; k < n; ++k) {
        const double rel = std::abs(v[k] - mean) / std::max(std::abs(mean), 1e-300);
        if (joints[k] < 0 || v[k] == mean) continue;
        const char* jn = mj_id2name(m, mjOBJ_JOINT, joints[k]);
        report.entries.push_back({name, k, jn ? jn : "joint" + std::to_string(joints[k]), v[k], mean, rel});
      }
    }
  }
  std::stable_sort(report.entries.begin(), report.entries.end(),
                   [](const Imperfection& a, const Imperfection& b) { return a.relative > b.relative; });
  report.dynamics = verifySymmetry(factory, options);
  return report;
}

std::string ImperfectionReport::summary(int top_k) const {
  std::ostringstream os;
  os << "imperfection (each limb against the median over the limbs):";
  if (entries.empty()) os << " none, every limb's parameters are equal";
  os << "\n";
  for (int k = 0; k < std::min<int>(top_k, entries.size()); ++k) {
    const Imperfection& e = entries[k];
    char buf[240];
    std::snprintf(buf, sizeof buf, "  limb %d (%s): %s %.4g vs median %.4g (%+.1f%%)\n", e.limb, e.joint.c_str(),
                  e.term.c_str(), e.value, e.mean, 100.0 * (e.value - e.mean) / (e.mean == 0 ? 1.0 : std::abs(e.mean)));
    os << buf;
  }
  double step = 0.0;
  std::string worst;
  for (const NamedError& e : dynamics.joints)
    if (e.error >= step) step = e.error, worst = e.name;
  os << "  one-step dynamics error: " << step << " (joint " << worst << ")";
  for (const PartCheck& p : dynamics.parts.parts) os << ", " << p.name << " " << p.worst;
  os << "\n";
  return os.str();
}

}  // namespace masa::task
