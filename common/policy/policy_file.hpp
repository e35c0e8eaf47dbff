// A trained policy as one file: what inference needs and nothing of the optimizer. It holds the
// run's resolved configuration (task, method, model, env: the task is rebuilt exactly as trained),
// the symmetry spec's own text (so the file works on a machine whose configs/ differ), and the
// model (policy and critic networks, observation and value normalizers).
//
// Layout: sealed (common/integrity/sealed_file.hpp: SHA-256, optionally signed), and inside the
// seal "MASAPOL1", u32 format version, [version 2 only: u32 action squash, 1 = tanh], u64 length +
// config YAML, u64 length + spec YAML, then ActorCritic::save(), nothing after it. Written
// atomically (tmp + rename).
//
// Versions: 1, the mean is the action (every PPO policy; still written for them, so that an older
// masa reads them); 2, a squash follows the version: tanh for masa_sac's policies, whose
// deterministic action is tanh(mean) (the loaded model's config().squash, honoured by actMean and
// the ONNX export). A version 2 file's critic is whatever its writer put there (masa_sac: a zero
// placeholder, SAC having no V(o)); its log-std is not a sampling noise (sampling is refused).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "common/config/run_config.hpp"
#include "common/integrity/sealed_file.hpp"
#include "common/model/actor_critic.hpp"
#include "common/symmetry/symmetry_spec.hpp"

namespace masa::policy {

struct LoadedPolicy {
  config::RunConfig config;
  std::string spec_text;
  sym::SymmetrySpec spec;
  std::unique_ptr<model::ActorCritic<float>> model;
  std::string source;     // the file it came from
  std::string integrity;  // how the file proved it is intact ("sealed (SHA-256 checked), signed by ...")
  std::optional<integrity::SignedRelease> release;  // the release its verified signature names, if any
};

// What a policy file is inside its seal.
inline constexpr integrity::FileKind kPolicyFileKind{"masa policy", "MASAPOL1"};

void savePolicyFile(const std::string& path, const config::RunConfig& rc, const model::ActorCritic<float>& model);

// Reads a policy file; throws std::runtime_error naming the file and what is wrong: a failed
// checksum or signature, a signature `rules` require and the file lacks, a malformed content.
LoadedPolicy loadPolicyFile(const std::string& path, const std::string& configs_dir = config::defaultConfigsDir(),
                            const integrity::ReadRules& rules = {});

// True when the file is a policy file by its first bytes (sealed as one, or an unsealed one's
// magic); checks nothing else.
bool isPolicyFile(const std::string& path);

// The equivariance MASA guarantees, measured on random observations (normalizer, mean, std,
// critic); throws when a MASA policy misses it by more than `tolerance`. Other methods: skipped.
// Returns the worst relative error found (0 when skipped).
double checkPolicySymmetry(LoadedPolicy& policy, double tolerance = 1e-4, int samples = 64);

}  // namespace masa::policy
