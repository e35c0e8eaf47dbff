// Files that prove they are intact. Every binary file masa writes (policy files, learner
// checkpoints, an actor's environments) is sealed: its content (the "payload", each format's own
// bytes) goes inside an envelope with the SHA-256 of the payload, and optionally an Ed25519
// signature. Readers check the envelope before they look at one byte of the payload, and refuse a
// file whose checksum or signature fails, naming the file and the reason.
//
// Layout (little-endian, like the formats inside):
//   "MASASEAL" | u32 envelope version (1) | u64 body length | 32-byte SHA-256 of the body |
//   body: u32 kind length, kind ("masa policy", ...), payload |
//   optional signature: "MASASIG1" | 32-byte Ed25519 public key | 64-byte signature of
//                       "masa sealed file signature 1\n" + the 52 bytes before the body,
//   or a release's:     "MASASIG2" | 32-byte public key | u64 release version | i64 signing time
//                       (Unix seconds) | 64-byte signature of "masa sealed file signature 2\n" +
//                       version + time + the 52 bytes before the body.
// The 52 bytes hold the body's SHA-256, so a signature covers the whole content (a policy's task,
// method and model); a release's also its version and time, so a reader can refuse an older
// release signed by the same trusted key (issue #55, item 4).
// The kind says what the payload is, so that one kind of file is never read as another.
//
// Files written before the seal (their payload alone, starting with the format's own magic) are
// read with a one-line warning on stderr naming the file, or refused where a signature is required
// (docs/reliability.md, "Files"). `masa_seal add FILE` seals such a file without changing its
// payload.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>

#include "common/integrity/ed25519_keys.hpp"

namespace masa::integrity {

struct FileKind {
  std::string_view name;          // stored in the seal, e.g. "masa policy"
  std::string_view legacy_magic;  // how the payload begins, which is how an unsealed file began
};

// A release's version and signing time, covered by its signature.
struct SignedRelease {
  std::uint64_t version = 0;
  std::int64_t signed_unix_s = 0;
};

// What a reader requires beyond an intact file.
struct ReadRules {
  const TrustedKeys* require_signed_by = nullptr;  // refuse a file not signed by one of these keys
  // Above 0 (with require_signed_by): refuse a file whose signature names no release or an older one.
  std::uint64_t min_release_version = 0;
  bool warn_unsealed = true;                       // the one-line warning for a file from before the seal
};

struct OpenedFile {
  std::string payload;
  bool sealed = false;                   // false: a file from before the seal (warned about)
  std::optional<PublicKeyBytes> signer;  // the key whose signature verified
  std::optional<SignedRelease> release;  // what that signature says of the release, when it does
  std::string describe() const;          // "sealed (SHA-256 checked), signed by ed25519:..." and the like
};

// The envelope around `payload`, unsigned.
std::string sealBytes(const FileKind& kind, std::string_view payload);
// Writes the sealed payload to `path` atomically (a temporary file beside it, flushed, renamed).
void writeSealedFile(const std::string& path, const FileKind& kind, std::string_view payload);
// The same file, its payload produced by `write_payload` into the stream it is given: the bytes are
// hashed and go to the disk as they come, never held whole in memory (a learner's replay is most of
// a gigabyte, and copying it cost more than writing it). If write_payload throws, or the disk
// refuses a byte, the old file at `path` stays as it was and the error goes on.
void writeSealedFileStreamed(const std::string& path, const FileKind& kind, const std::function<void(std::ostream&)>& write_payload);

// Checks a sealed file's bytes (`name` says where they came from) and returns its payload; throws
// std::runtime_error "<name>: <reason>" when the file is not intact, not of `kind`, or not signed as
// `rules` require. A file from before the seal (its bytes start with kind.legacy_magic) is returned
// as it is, with a warning on stderr, unless `rules` require a signature.
OpenedFile openSealedBytes(std::string bytes, const std::string& name, const FileKind& kind, const ReadRules& rules = {});
OpenedFile readSealedFile(const std::string& path, const FileKind& kind, const ReadRules& rules = {});

// Whether the file looks like `kind` (sealed as that kind, or its unsealed magic); checks nothing.
bool looksLikeKind(const std::string& path, const FileKind& kind);
// The kind a sealed file claims, "" when it is not sealed; checks nothing.
std::string sealedKindOf(const std::string& path);

// Signs a sealed file in place (atomically), replacing any signature it had; the file's seal is
// checked first, whatever its kind. With `release`, the signature covers its version and time too.
void signSealedFile(const std::string& path, const SigningKey& key, const std::optional<SignedRelease>& release = std::nullopt);

}  // namespace masa::integrity
