// masa_export: a trained policy as an ONNX file that a robot stack runs without masa.
//   masa_export tasks/a1_beam/policy/policy.bin a1_beam.onnx
//   masa_export runs/a1_beam_masa_20261130_120000 a1.onnx        (a run directory: its policy.bin)
//   masa_export POLICY a1.onnx --reference a1_reference.txt --samples 64
// --reference also writes random observations and masa's own action means for them, one sample
// a row, so that the file can be checked against masa in the runtime that will run it. A MASA
// policy's equivariance is checked on load, as masa_deploy does. What the file holds:
// common/onnx/policy_onnx.hpp.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <random>

#include "common/core/build_info.hpp"
#include "common/onnx/policy_onnx.hpp"
#include "common/policy/policy_file.hpp"

using namespace masa;
namespace fs = std::filesystem;

namespace {

std::string policyPath(const std::string& target) {
  const fs::path p(target);
  if (fs::is_directory(p)) {
    if (!fs::exists(p / "policy.bin"))
      throw std::runtime_error(target + ": a directory without policy.bin (masa_eval --save-policy makes one from a checkpoint)");
    return (p / "policy.bin").string();
  }
  if (!fs::exists(p)) throw std::runtime_error(target + ": no such file or directory");
  return target;
}

// Observations spread around the normalizer's statistics (2 standard deviations), so that the
// network sees inputs like a robot's, hidden units on both sides of the activations' knees.
void writeReference(policy::LoadedPolicy& p, const std::string& path, int samples, uint64_t seed) {
  auto& model = *p.model;
  const auto& norm = model.obsNormalizer();
  Rng rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Mat<float> obs(model.obsDim(), samples);
  for (int b = 0; b < samples; ++b)
    for (int d = 0; d < model.obsDim(); ++d)
      obs(d, b) = static_cast<float>(norm.mean()(d) + 2.0 * std::sqrt(norm.var()(d)) * normal(rng));
  const Mat<float> mean = model.actMean(obs);
  Vec<float> log_std(model.actDim());
  model.logStd(log_std);

  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error(path + ": cannot write");
  std::fprintf(f, "# masa_export reference of %s: one sample a row, the observation then masa's action_mean\n",
               p.source.c_str());
  std::fprintf(f, "# obs_dim %d act_dim %d samples %d seed %llu\n# log_std", model.obsDim(), model.actDim(), samples,
               static_cast<unsigned long long>(seed));
  // %.9g: a float32 read back from nine significant digits is the same float.
  for (int j = 0; j < model.actDim(); ++j) std::fprintf(f, " %.9g", log_std(j));
  std::fprintf(f, "\n");
  for (int b = 0; b < samples; ++b) {
    for (int d = 0; d < model.obsDim(); ++d) std::fprintf(f, "%s%.9g", d ? " " : "", obs(d, b));
    for (int j = 0; j < model.actDim(); ++j) std::fprintf(f, " %.9g", mean(j, b));
    std::fprintf(f, "\n");
  }
  if (std::fclose(f) != 0) throw std::runtime_error(path + ": write failed");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Export a trained masa policy's mean, normalizer included, to an ONNX file"};
  app.set_version_flag("--version", masa::buildCommit());
  std::string target, out, reference;
  int samples = 64;
  uint64_t seed = 0;
  app.add_option("policy", target, "policy file (policy.bin) or run directory")->required();
  app.add_option("out", out, "the ONNX file to write (e.g. a1_beam.onnx)")->required();
  app.add_option("--reference", reference, "also write random observations and masa's action means for them");
  app.add_option("--samples", samples, "rows of the reference")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "seed of the reference's observations")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    policy::LoadedPolicy p = policy::loadPolicyFile(policyPath(target));
    policy::checkPolicySymmetry(p);
    onnx_export::writePolicyOnnx(p, out);
    std::printf("wrote %s: %s %s, observation [batch, %d] -> action_mean [batch, %d], log_std [%d]\n", out.c_str(),
                p.config.task.c_str(), model::methodName(p.config.method).c_str(), p.model->obsDim(),
                p.model->actDim(), p.model->actDim());
    if (!reference.empty()) {
      writeReference(p, reference, samples, seed);
      std::printf("wrote %s: %d observations and masa's action means\n", reference.c_str(), samples);
    }
  } catch (const std::exception& e) {
    std::cerr << "masa_export: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
