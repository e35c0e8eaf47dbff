#include "common/policy/policy_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

#include "common/core/binary_io.hpp"
#include "common/core/config_error.hpp"
#include "common/model/equivariance_check.hpp"

namespace masa::policy {
namespace fs = std::filesystem;
namespace {

constexpr char kMagic[8] = {'M', 'A', 'S', 'A', 'P', 'O', 'L', '1'};
constexpr uint32_t kFormatPlain = 1;     // the mean is the action
constexpr uint32_t kFormatSquashed = 2;  // a u32 squash after the version
constexpr uint32_t kSquashTanh = 1;
constexpr uint64_t kMaxText = 16u << 20;  // a config or spec larger than this is a corrupt file

void writeText(std::ostream& os, const std::string& s) {
  const uint64_t n = s.size();
  io::writePod(os, n);
  os.write(s.data(), static_cast<std::streamsize>(n));
}

std::string readText(std::istream& is, const std::string& path, const char* what) {
  uint64_t n = 0;
  if (!io::readPod(is, n) || n > kMaxText) throw std::runtime_error(path + ": truncated or corrupt policy file (" + what + ")");
  std::string s(n, '\0');
  is.read(s.data(), static_cast<std::streamsize>(n));
  if (!is) throw std::runtime_error(path + ": truncated policy file (" + what + ")");
  return s;
}

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open the symmetry spec");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

void savePolicyFile(const std::string& path, const config::RunConfig& rc, const model::ActorCritic<float>& model) {
  const std::string spec_text = readWholeFile(rc.spec_path);
  std::ostringstream os(std::ios::binary);
  os.write(kMagic, sizeof kMagic);
  if (model.config().squash == model::ActionSquash::kNone) {
    io::writePod(os, kFormatPlain);
  } else {
    io::writePod(os, kFormatSquashed);
    io::writePod(os, kSquashTanh);
  }
  writeText(os, config::dumpResolved(rc));
  writeText(os, spec_text);
  model.save(os);
  if (!os) throw std::runtime_error(path + ": cannot serialize the policy");
  integrity::writeSealedFile(path, kPolicyFileKind, os.view());
}

bool isPolicyFile(const std::string& path) { return integrity::looksLikeKind(path, kPolicyFileKind); }

LoadedPolicy loadPolicyFile(const std::string& path, const std::string& configs_dir, const integrity::ReadRules& rules) {
  if (!fs::exists(path)) throw std::runtime_error(path + ": cannot open the policy file (no such file)");
  const integrity::OpenedFile file = integrity::readSealedFile(path, kPolicyFileKind, rules);
  std::istringstream is(file.payload, std::ios::binary);
  char magic[sizeof kMagic] = {};
  is.read(magic, sizeof magic);
  if (!is || std::memcmp(magic, kMagic, sizeof magic) != 0)
    throw std::runtime_error(path + ": not a masa policy file (bad magic)");
  uint32_t version = 0;
  if (!io::readPod(is, version) || (version != kFormatPlain && version != kFormatSquashed))
    throw std::runtime_error(path + ": policy file format " + std::to_string(version) + ", this masa reads " +
                             std::to_string(kFormatPlain) + " and " + std::to_string(kFormatSquashed));
  model::ActionSquash squash = model::ActionSquash::kNone;
  if (version == kFormatSquashed) {
    uint32_t s = 0;
    if (!io::readPod(is, s)) throw std::runtime_error(path + ": truncated policy file (squash)");
    if (s != kSquashTanh) throw std::runtime_error(path + ": unknown action squash " + std::to_string(s) + " (corrupt policy file)");
    squash = model::ActionSquash::kTanh;
  }
  LoadedPolicy p;
  p.source = path;
  p.integrity = file.describe();
  p.release = file.release;
  const std::string config_text = readText(is, path, "config");
  p.spec_text = readText(is, path, "spec");
  try {
    p.config = config::loadRunConfigText(configs_dir, config_text, path + " (its config)");
    p.spec = sym::SymmetrySpec::parseString(p.spec_text, path + " (its spec)");
  } catch (const ConfigError& e) {
    throw std::runtime_error(e.what());
  }
  p.config.model.squash = squash;
  p.model = std::make_unique<model::ActorCritic<float>>(p.spec, p.config.model);
  p.model->load(is, path);
  if (is.peek() != std::char_traits<char>::eof()) throw std::runtime_error(path + ": bytes after the model (corrupt policy file)");
  return p;
}

double checkPolicySymmetry(LoadedPolicy& policy, double tolerance, int samples) {
  if (policy.config.method != model::Method::kMasa) return 0.0;
  auto& model = *policy.model;
  // Observations within 2 std of the normalizer's statistics (where the policy was trained; the
  // normalizer does not clip), actions around 0.
  std::mt19937_64 rng(12345);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  const auto& norm = model.obsNormalizer();
  Mat<float> obs(model.obsDim(), samples), act(model.actDim(), samples);
  for (int b = 0; b < samples; ++b) {
    for (int d = 0; d < model.obsDim(); ++d) {
      const float z = std::clamp(normal(rng), -2.0f, 2.0f);
      obs(d, b) = static_cast<float>(norm.mean()(d) + std::sqrt(norm.var()(d)) * z);
    }
    for (int d = 0; d < model.actDim(); ++d) act(d, b) = 0.5f * normal(rng);
  }
  const model::EquivarianceReport r = model::checkEquivariance<float>(model, obs, act);
  if (!(r.worst() <= tolerance)) {
    std::ostringstream msg;
    msg << policy.source << ": the MASA policy is not equivariant under its spec (mean error " << r.mean_error
        << ", log-prob " << r.logp_error << ", value " << r.value_error << ", tolerance " << tolerance
        << "): the file does not match its spec, or is corrupt";
    throw std::runtime_error(msg.str());
  }
  return r.worst();
}

}  // namespace masa::policy
