// masa_seal: what proves a masa file intact, and who signed it.
//   masa_seal check FILE... [--trusted-keys KEYS]    the seal of each file (and its signer); exit 1 on any refusal
//   masa_seal add FILE...                            seals files written before masa sealed its files
//   masa_seal keygen --private release.key --public release.pub
//   masa_seal sign POLICY --key release.key          signs a sealed file (masa_deploy --require-signed)
// Keys are Ed25519 PEM files (OpenSSL); a private key file is made with mode 0600 and refused when
// others may read it. Keys go as files, never on the command line.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "actors/environments_snapshot.hpp"
#include "common/core/build_info.hpp"
#include "common/integrity/ed25519_keys.hpp"
#include "common/integrity/sealed_file.hpp"
#include "common/policy/policy_file.hpp"
#include "learner/run_dir/checkpoint.hpp"

using namespace masa;

namespace {

const integrity::FileKind kKinds[] = {policy::kPolicyFileKind, learner::kCheckpointFileKind, actor::kEnvironmentsFileKind};

// The kind a file is by its first bytes, or null.
const integrity::FileKind* kindOf(const std::string& path) {
  for (const integrity::FileKind& k : kKinds)
    if (integrity::looksLikeKind(path, k)) return &k;
  return nullptr;
}

int check(const std::vector<std::string>& files, const std::string& trusted_path) {
  integrity::TrustedKeys trusted;
  integrity::ReadRules rules;
  if (!trusted_path.empty()) {
    trusted = integrity::TrustedKeys::load(trusted_path);
    rules.require_signed_by = &trusted;
  }
  int refused = 0;
  for (const std::string& f : files) {
    try {
      const integrity::FileKind* kind = kindOf(f);
      if (!kind) throw std::runtime_error(f + ": not a masa policy, checkpoint or actor environments file");
      const integrity::OpenedFile opened = integrity::readSealedFile(f, *kind, rules);
      std::printf("%s: %s, %s\n", f.c_str(), std::string(kind->name).c_str(), opened.describe().c_str());
    } catch (const std::exception& e) {
      std::printf("REFUSED %s\n", e.what());
      ++refused;
    }
  }
  return refused == 0 ? 0 : 1;
}

int add(const std::vector<std::string>& files) {
  for (const std::string& f : files) {
    if (!integrity::sealedKindOf(f).empty()) {
      std::printf("%s: already sealed\n", f.c_str());
      continue;
    }
    const integrity::FileKind* kind = kindOf(f);
    if (!kind) throw std::runtime_error(f + ": not a masa policy, checkpoint or actor environments file");
    // A policy is loaded first, so that a damaged old file is not certified intact.
    integrity::ReadRules quiet;
    quiet.warn_unsealed = false;  // (sealing it is the answer to the warning)
    if (kind->name == policy::kPolicyFileKind.name) (void)policy::loadPolicyFile(f, config::defaultConfigsDir(), quiet);
    std::ifstream in(f, std::ios::binary);
    const std::string payload((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    integrity::writeSealedFile(f, *kind, payload);
    std::printf("%s: sealed as a %s file (%zu payload bytes, unchanged)\n", f.c_str(), std::string(kind->name).c_str(), payload.size());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"masa_seal: checksums and signatures of masa's files"};
  app.set_version_flag("--version", masa::buildCommit());
  app.require_subcommand(1);
  std::vector<std::string> files;
  std::string trusted, private_path, public_path, key_path, target;
  std::uint64_t release_version = 0;

  auto* check_cmd = app.add_subcommand("check", "check each file's seal (and signer)");
  check_cmd->add_option("files", files, "masa files")->required();
  check_cmd->add_option("--trusted-keys", trusted, "also require a signature by one of these public keys (file or directory)");
  auto* add_cmd = app.add_subcommand("add", "seal files written before masa sealed its files (their content unchanged)");
  add_cmd->add_option("files", files, "masa files")->required()->check(CLI::ExistingFile);
  auto* keygen_cmd = app.add_subcommand("keygen", "make an Ed25519 key pair");
  keygen_cmd->add_option("--private", private_path, "private key file to create (mode 0600)")->required();
  keygen_cmd->add_option("--public", public_path, "public key file to create")->required();
  auto* sign_cmd = app.add_subcommand("sign", "sign a sealed file with a private key");
  sign_cmd->add_option("file", target, "a sealed masa file (a policy)")->required()->check(CLI::ExistingFile);
  sign_cmd->add_option("--key", key_path, "the private key file")->required()->check(CLI::ExistingFile);
  sign_cmd->add_option("--release-version", release_version, "sign as this release (1 and up), with the time: "
                       "masa_deploy --min-policy-version refuses older ones")->check(CLI::Range(std::uint64_t{1}, UINT64_MAX));
  CLI11_PARSE(app, argc, argv);

  try {
    if (check_cmd->parsed()) return check(files, trusted);
    if (add_cmd->parsed()) return add(files);
    if (keygen_cmd->parsed()) {
      const integrity::PublicKeyBytes pub = integrity::generateKeyPair(private_path, public_path);
      std::printf("key pair %s: private %s (mode 0600), public %s\n", integrity::keyFingerprint(pub).c_str(), private_path.c_str(),
                  public_path.c_str());
      return 0;
    }
    const integrity::SigningKey key = integrity::SigningKey::load(key_path);
    std::optional<integrity::SignedRelease> release;
    if (release_version > 0) release = integrity::SignedRelease{release_version, static_cast<std::int64_t>(std::time(nullptr))};
    integrity::signSealedFile(target, key, release);
    std::printf("%s: signed by %s%s\n", target.c_str(), integrity::keyFingerprint(key.publicKey()).c_str(),
                release ? (" as release " + std::to_string(release_version)).c_str() : "");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_seal: %s\n", e.what());
    return 2;
  }
}
