// Ed25519 keys (OpenSSL EVP) for signing policy files: a release key, or a learner's. A private key
// lives in a PEM file of mode 0600 that only its owner reads; a public key in a PEM file anyone may
// read. Keys travel as files, never on a command line (`ps` shows those to every user).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace masa::integrity {

using PublicKeyBytes = std::array<std::uint8_t, 32>;
using SignatureBytes = std::array<std::uint8_t, 64>;

// "ed25519:" and 16 hex digits of the SHA-256 of the raw public key: what logs and errors show.
std::string keyFingerprint(const PublicKeyBytes& key);

// A private key, able to sign.
class SigningKey {
 public:
  // Reads a PEM private key; throws std::runtime_error naming the file when it is missing, not an
  // Ed25519 key, readable by others than its owner, owned by another user, or in a directory
  // another user owns or others may write (readOwnedFile, owned_file.hpp).
  static SigningKey load(const std::string& path);
  // A new key that lives only in this process's memory (an MPI job's processes: nothing to carry).
  static SigningKey generate();
  SignatureBytes sign(std::string_view message) const;
  PublicKeyBytes publicKey() const { return public_; }

 private:
  struct Pkey;
  explicit SigningKey(std::shared_ptr<Pkey> key);
  std::shared_ptr<Pkey> key_;
  PublicKeyBytes public_{};
};

// Makes a new key pair: the private key into `private_path` (created, mode 0600; an existing file is
// never overwritten), the public key into `public_path`. Returns the public key.
PublicKeyBytes generateKeyPair(const std::string& private_path, const std::string& public_path);

// Whether `signature` over `message` was made by the private key of `key`.
bool verifySignature(const PublicKeyBytes& key, std::string_view message, const SignatureBytes& signature);

// The public keys a reader trusts.
class TrustedKeys {
 public:
  // A PEM file of one or more public keys, or a directory whose *.pub files are such files. Throws
  // std::runtime_error naming the file when one is not a PEM Ed25519 public key, or none is found.
  static TrustedKeys load(const std::string& path);
  void add(const PublicKeyBytes& key) { keys_.push_back(key); }
  bool contains(const PublicKeyBytes& key) const;
  const std::vector<PublicKeyBytes>& keys() const { return keys_; }
  const std::string& source() const { return source_; }

 private:
  std::vector<PublicKeyBytes> keys_;
  std::string source_;
};

}  // namespace masa::integrity
