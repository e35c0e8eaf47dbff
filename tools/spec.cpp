// masa_spec: inspect and check a symmetry spec.
//   masa_spec configs/specs/trifinger_lift.yaml            summary, group laws, MASA equivariance
//   masa_spec configs/specs/trifinger_lift.yaml --maps     also print T_1 entry by entry
// Exit status 0 when every check passes, 1 when one fails, 2 on a malformed spec.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "common/core/build_info.hpp"
#include "common/core/config_error.hpp"
#include "common/model/equivariance_check.hpp"
#include "common/symmetry/symmetry_spec.hpp"

using namespace masa;

namespace {

double groupLawError(const std::vector<Eigen::MatrixXd>& t) {
  const int n = static_cast<int>(t.size());
  double worst = (t[0] - Eigen::MatrixXd::Identity(t[0].rows(), t[0].cols())).cwiseAbs().maxCoeff();
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) worst = std::max(worst, (t[i] * t[j] - t[(i + j) % n]).cwiseAbs().maxCoeff());
  return worst;
}

void printMap(const sym::SparseMap& m, const std::vector<std::string>& names) {
  for (int r = 0; r < m.rows(); ++r) {
    std::printf("  %-34s <-", names[r].c_str());
    for (int k = m.rowStart()[r]; k < m.rowStart()[r + 1]; ++k)
      std::printf(" %+.4g*%s", m.values()[k], names[m.colIndex()[k]].c_str());
    std::printf("\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Inspect a masa symmetry spec and check its group laws and MASA's equivariance"};
  app.set_version_flag("--version", masa::buildCommit());
  std::string path;
  bool show_maps = false;
  std::uint64_t seed = 0;
  app.add_option("spec", path, "symmetry spec YAML file")->required();
  app.add_flag("--maps", show_maps, "print T_1 for observations and actions");
  app.add_option("--seed", seed, "seed of the random network and inputs used for the equivariance check");
  CLI11_PARSE(app, argc, argv);

  sym::SymmetrySpec spec;
  try {
    spec = sym::SymmetrySpec::load(path);
  } catch (const ConfigError& e) {
    std::cerr << "masa_spec: " << e.what() << "\n";
    return 2;
  }
  const int n = spec.numAgents();
  std::printf("%s: %s of order %d, %d agents\n", spec.name().c_str(),
              spec.group().type == sym::GroupType::kReflection ? "reflection" : "rotation", n, n);
  std::printf("  observation %d = central %d + %d x limb %d\n", spec.obsDim(), spec.obsCentralDim(), n,
              spec.obsLimbDim());
  std::printf("  action      %d = central %d + %d x limb %d\n", spec.actDim(), spec.actCentralDim(), n,
              spec.actLimbDim());
  if (show_maps) {
    std::printf("T_1 on observations (row <- sum of coefficient*source):\n");
    printMap(spec.obsTransform(1 % n), spec.obsNames());
    std::printf("T_1 on actions:\n");
    printMap(spec.actTransform(1 % n), spec.actNames());
  }

  std::vector<Eigen::MatrixXd> to, ta;
  for (int i = 0; i < n; ++i) {
    to.push_back(spec.obsTransform(i).toDense());
    ta.push_back(spec.actTransform(i).toDense());
  }
  const double law = std::max(groupLawError(to), groupLawError(ta));
  const bool law_ok = law < 1e-12;
  std::printf("group laws T_0 = I, T_i T_j = T_(i+j mod N): max error %.2e  %s\n", law, law_ok ? "ok" : "FAILED");

  model::ModelConfig cfg;
  cfg.policy_hidden = {64, 64};
  cfg.critic_hidden = {64, 64};
  cfg.policy_last_layer_scale = 1.0;
  model::ActorCritic<double> masa_model(spec, cfg);
  Rng rng(seed);
  masa_model.initialize(rng);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd obs(spec.obsDim(), 64), act(spec.actDim(), 64);
  for (auto* m : {&obs, &act})
    for (Eigen::Index k = 0; k < m->size(); ++k) m->data()[k] = normal(rng);
  masa_model.obsNormalizer().update(obs);
  const auto r = model::checkEquivariance<double>(masa_model, obs, act);
  const bool eq_ok = r.worst() < 1e-9;
  std::printf("MASA equivariance on 64 random inputs: mean %.2e, log-prob %.2e, value %.2e  %s\n", r.mean_error,
              r.logp_error, r.value_error, eq_ok ? "ok" : "FAILED");
  return law_ok && eq_ok ? 0 : 1;
}
