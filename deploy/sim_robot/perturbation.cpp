#include "deploy/sim_robot/perturbation.hpp"

#include <cstdio>
#include <random>
#include <stdexcept>

namespace masa::deploy {
namespace {

const std::string kPrefix = "env.randomization.";

std::string keyOf(std::string key) {
  if (key.rfind(kPrefix, 0) == 0) return key.substr(kPrefix.size());
  if (key.rfind("randomization.", 0) == 0) return key.substr(std::string("randomization.").size());
  return key;
}

}  // namespace

YAML::Node perturbedEnv(const YAML::Node& env, const std::vector<std::string>& assignments, const std::string& file,
                        std::map<std::string, std::string>& origin, bool* perturbed) {
  *perturbed = !assignments.empty() || !file.empty();
  if (!*perturbed) return env;
  YAML::Node out = YAML::Clone(env);
  if (!out.IsMap()) out = YAML::Node(YAML::NodeType::Map);
  YAML::Node section(YAML::NodeType::Map);
  // The training randomization's origins no longer apply.
  for (auto it = origin.begin(); it != origin.end();)
    it = it->first.rfind("env.randomization", 0) == 0 ? origin.erase(it) : std::next(it);
  if (!file.empty()) {
    YAML::Node doc;
    try {
      doc = YAML::LoadFile(file);
    } catch (const YAML::Exception& e) {
      throw std::runtime_error("--perturb-file " + file + ": " + e.what());
    }
    if (doc["env"] && doc["env"]["randomization"]) doc = doc["env"]["randomization"];
    else if (doc["randomization"]) doc = doc["randomization"];
    if (!doc.IsMap()) throw std::runtime_error("--perturb-file " + file + ": expected a mapping of env.randomization keys");
    for (const auto& kv : doc) {
      const std::string key = keyOf(kv.first.as<std::string>());
      section[key] = kv.second;
      origin[kPrefix + key] = file;
    }
  }
  for (const std::string& a : assignments) {
    const auto eq = a.find('=');
    if (eq == std::string::npos || eq == 0)
      throw std::runtime_error("--perturb " + a + ": expected KEY=VALUE, e.g. env.randomization.mass_scale=1.2");
    const std::string key = keyOf(a.substr(0, eq));
    try {
      section[key] = YAML::Load(a.substr(eq + 1));
    } catch (const YAML::Exception& e) {
      throw std::runtime_error("--perturb " + a + ": " + e.what());
    }
    origin[kPrefix + key] = "--perturb";
  }
  out["randomization"] = section;
  return out;
}

std::string describePerturbation(const task::Task& task) {
  const mjModel* m = task.model();
  const task::PhysicsRandomization& p = *task.randomization();
  double mass = 0, mass0 = 0;
  for (int b = 0; b < m->nbody; ++b) mass += m->body_mass[b], mass0 += p.nominalMass(b);
  // The mean ratio over the elements that have the property at all.
  auto meanRatio = [](int n, auto now, auto nominal) {
    double sum = 0;
    int count = 0;
    for (int k = 0; k < n; ++k)
      if (nominal(k) != 0.0) sum += now(k) / nominal(k), ++count;
    return count ? sum / count : 1.0;
  };
  const double friction = meanRatio(m->ngeom, [&](int g) { return m->geom_friction[3 * g]; }, [&](int g) { return p.nominalFriction(g); });
  const double damping = meanRatio(m->nv, [&](int v) { return m->dof_damping[v]; }, [&](int v) { return p.nominalDamping(v); });
  const double gear = meanRatio(m->nu, [&](int a) { return m->actuator_gear[6 * a]; }, [&](int a) { return p.nominalGear(a); });
  char text[256];
  std::snprintf(text, sizeof text, "mass %.3f kg (model %.3f kg), geom friction x%.3f, joint damping x%.3f, motor strength x%.3f",
                mass, mass0, friction, damping, gear);
  return text;
}

StateNoise::StateNoise(const task::RandomizationConfig& config, int num_joints, Rng& rng)
    : std_(config.obs_noise_std), rng_(rng()) {
  if (config.obs_bias > 0.0) {
    std::uniform_real_distribution<double> u(-config.obs_bias, config.obs_bias);
    bias_.resize(2 * static_cast<std::size_t>(num_joints));
    for (double& b : bias_) b = u(rng);
  }
}

void StateNoise::apply(masa::lcmt_robot_state& st) {
  const int n = st.num_joints;
  std::normal_distribution<double> noise(0.0, std_ > 0.0 ? std_ : 1.0);
  for (int k = 0; k < n; ++k) {
    double& q = st.joint_position[k];
    double& v = st.joint_velocity[k];
    if (!bias_.empty()) q += bias_[k], v += bias_[n + k];
    if (std_ > 0.0) q += noise(rng_), v += noise(rng_);
  }
}

}  // namespace masa::deploy
