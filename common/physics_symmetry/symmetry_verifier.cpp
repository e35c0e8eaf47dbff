#include "common/physics_symmetry/symmetry_verifier.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace masa::task {
namespace {

void raise(std::vector<NamedError>& v, int k, double e) { v[k].error = std::max(v[k].error, e); }

// Observations are floats: compare relative to their size (1 + |want|).
double relative(float got, float want) { return std::abs(double(got) - double(want)) / (1.0 + std::abs(double(want))); }

// Per-joint distance between two simulator states: qpos (free-joint orientations as rotations,
// so q and -q agree) and qvel.
void compareJoints(const mjModel* m, const mjData* a, const mjData* b, std::vector<NamedError>& out) {
  for (int j = 0; j < m->njnt; ++j) {
    const int qa = m->jnt_qposadr[j], va = m->jnt_dofadr[j];
    double e = 0.0;
    int npos = 1, nvel = 1;
    if (m->jnt_type[j] == mjJNT_FREE) {
      npos = 3;
      nvel = 6;
      double same = 0.0, flipped = 0.0;
      for (int k = 3; k < 7; ++k) {
        same = std::max(same, std::abs(a->qpos[qa + k] - b->qpos[qa + k]));
        flipped = std::max(flipped, std::abs(a->qpos[qa + k] + b->qpos[qa + k]));
      }
      e = std::min(same, flipped);
    } else if (m->jnt_type[j] == mjJNT_BALL) {
      npos = 4;
      nvel = 3;
    }
    for (int k = 0; k < npos; ++k) e = std::max(e, std::abs(a->qpos[qa + k] - b->qpos[qa + k]));
    for (int k = 0; k < nvel; ++k) e = std::max(e, std::abs(a->qvel[va + k] - b->qvel[va + k]));
    raise(out, j, e);
  }
}

}  // namespace

double SymmetryReport::worst() const {
  double w = reward_error;
  for (const auto* v : {&observation_map, &observation, &joints})
    for (const auto& e : *v) w = std::max(w, e.error);
  return w;
}

std::string SymmetryReport::summary(int top_k) const {
  std::ostringstream os;
  os << (passed() ? "PASS" : "FAIL") << ": worst error " << worst() << " (tolerance " << tolerance << "), reward "
     << reward_error << ", termination mismatches " << termination_mismatches << "\n";
  auto list = [&](const char* title, std::vector<NamedError> v) {
    std::sort(v.begin(), v.end(), [](const NamedError& a, const NamedError& b) { return a.error > b.error; });
    os << "  " << title << ":";
    for (int k = 0; k < std::min<int>(top_k, static_cast<int>(v.size())); ++k) {
      char buf[160];
      std::snprintf(buf, sizeof buf, " %s %.2e%s", v[k].name.c_str(), v[k].error,
                    v[k].error > tolerance ? " (!)" : "");
      os << buf;
    }
    os << "\n";
  };
  list("observation map obs(T s) vs T obs(s)", observation_map);
  list("observation after step", observation);
  list("joints after step", joints);
  os << parts.summary();
  return os.str();
}

SymmetryReport verifySymmetry(const TaskFactory& factory, const SymmetryVerifierOptions& options) {
  std::unique_ptr<Task> a = factory.create(), b = factory.create();
  const sym::SymmetrySpec& spec = a->spec();
  const mjModel* m = a->model();
  const int n = spec.numAgents(), od = spec.obsDim(), ad = spec.actDim();

  SymmetryReport report;
  report.tolerance = options.tolerance;
  for (const auto& name : spec.obsNames()) {
    report.observation_map.push_back({name, 0.0});
    report.observation.push_back({name, 0.0});
  }
  for (int j = 0; j < m->njnt; ++j) {
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    report.joints.push_back({name ? name : "joint" + std::to_string(j), 0.0});
  }

  Rng rng(options.seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_int_distribution<int> warmup(0, options.max_warmup_steps);
  Eigen::VectorXf act(ad), tact(ad);
  Eigen::VectorXf obs_a(od), obs_b(od), tobs(od);

  for (int s = 0; s < options.num_states; ++s) {
    a->reset(rng);
    for (int w = warmup(rng); w > 0; --w) {
      for (int k = 0; k < ad; ++k) act(k) = unit(rng);
      const StepOutcome o = a->step(act.data());
      if (o.terminated || o.truncated) a->reset(rng);
    }
    for (int i = 1; i < n; ++i) {
      b->copyStateFrom(*a);
      b->applySymmetry(i);
      a->observe(obs_a.data());
      b->observe(obs_b.data());
      spec.obsTransform(i).apply<float>(obs_a, tobs);
      for (int d = 0; d < od; ++d) raise(report.observation_map, d, relative(obs_b(d), tobs(d)));

      // Step a copy of the original (so `a` keeps its trajectory for the next element).
      std::unique_ptr<Task> c = factory.create();
      c->copyStateFrom(*a);
      for (int t = 0; t < options.steps; ++t) {
        for (int k = 0; k < ad; ++k) act(k) = unit(rng);
        spec.actTransform(i).apply<float>(act, tact);
        const StepOutcome oc = c->step(act.data());
        const StepOutcome ob = b->step(tact.data());
        report.reward_error = std::max(report.reward_error, std::abs(oc.reward - ob.reward));
        if (oc.terminated != ob.terminated) ++report.termination_mismatches;
        c->observe(obs_a.data());
        b->observe(obs_b.data());
        spec.obsTransform(i).apply<float>(obs_a, tobs);
        for (int d = 0; d < od; ++d) raise(report.observation, d, relative(obs_b(d), tobs(d)));
        if (oc.terminated || ob.terminated) break;
      }
      c->applySymmetry(i);
      compareJoints(m, c->data(), b->data(), report.joints);
    }
  }
  report.parts = diagnoseSymmetry(factory, {.num_states = std::min(options.num_states, options.diagnosis_states),
                                            .max_warmup_steps = options.max_warmup_steps,
                                            .seed = options.seed,
                                            .tolerance = options.tolerance});
  return report;
}

}  // namespace masa::task
