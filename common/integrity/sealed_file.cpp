#include "common/integrity/sealed_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <stdexcept>
#include <streambuf>
#include <vector>

#include "common/integrity/sha256.hpp"

namespace masa::integrity {
namespace {

constexpr std::string_view kSealMagic = "MASASEAL";
constexpr std::uint32_t kEnvelopeVersion = 1;
constexpr std::size_t kHeaderBytes = 8 + 4 + 8 + 32;
constexpr std::string_view kSignatureMagic = "MASASIG1";
constexpr std::size_t kSignatureBytes = 8 + 32 + 64;
constexpr std::string_view kSignatureContext = "masa sealed file signature 1\n";
constexpr std::string_view kReleaseSignatureMagic = "MASASIG2";
constexpr std::size_t kReleaseSignatureBytes = 8 + 32 + 8 + 8 + 64;
constexpr std::string_view kReleaseSignatureContext = "masa sealed file signature 2\n";
constexpr std::uint32_t kMaxKindBytes = 64;
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{1} << 34;  // 16 GiB: larger is not a masa file

template <class T>
T podAt(const std::string& bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof v);
  return v;
}

template <class T>
void appendPod(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// What the envelope says once every check passed.
struct Envelope {
  std::string kind;
  std::size_t payload_offset = 0, payload_size = 0, body_end = 0;
  std::optional<PublicKeyBytes> signer;
  std::optional<SignedRelease> release;
};

[[noreturn]] void refuse(const std::string& name, const std::string& why) { throw std::runtime_error(name + ": " + why); }

std::string signedMessage(const std::string& bytes) {
  return std::string(kSignatureContext).append(bytes, 0, kHeaderBytes);
}

std::string releaseSignedMessage(const std::string& bytes, const SignedRelease& release) {
  std::string out(kReleaseSignatureContext);
  appendPod(out, release.version);
  appendPod(out, release.signed_unix_s);
  return out.append(bytes, 0, kHeaderBytes);
}

// Checks the envelope: lengths against the file size, the body's SHA-256, the kind's bounds, and a
// signature when there is one. Nothing of the body is looked at before its checksum matched.
Envelope checkEnvelope(const std::string& bytes, const std::string& name) {
  if (bytes.size() < kHeaderBytes)
    refuse(name, "truncated (" + std::to_string(bytes.size()) + " bytes, shorter than the seal's header)");
  const auto version = podAt<std::uint32_t>(bytes, 8);
  if (version != kEnvelopeVersion)
    refuse(name, "sealed with envelope version " + std::to_string(version) + ", this masa reads " + std::to_string(kEnvelopeVersion) +
                     " (a newer masa's file, or a damaged one)");
  const auto body = podAt<std::uint64_t>(bytes, 12);
  const std::size_t after_header = bytes.size() - kHeaderBytes;
  bool has_signature = false, has_release = false;
  if (body == after_header) {
    has_signature = false;
  } else if (after_header >= kSignatureBytes && body == after_header - kSignatureBytes) {
    has_signature = true;
  } else if (after_header >= kReleaseSignatureBytes && body == after_header - kReleaseSignatureBytes) {
    has_release = true;
  } else {
    refuse(name, "checksum mismatch (file corrupted or truncated: the seal holds " + std::to_string(body) + " bytes, the file " +
                     std::to_string(after_header) + ")");
  }
  Digest stored;
  std::memcpy(stored.data(), bytes.data() + 20, stored.size());
  if (sha256(std::string_view(bytes).substr(kHeaderBytes, body)) != stored)
    refuse(name, "checksum mismatch (file corrupted or truncated)");

  Envelope e;
  e.body_end = kHeaderBytes + body;
  const auto kind_bytes = body >= 4 ? podAt<std::uint32_t>(bytes, kHeaderBytes) : kMaxKindBytes + 1;
  if (kind_bytes > kMaxKindBytes || 4 + std::uint64_t{kind_bytes} > body) refuse(name, "a seal without a valid kind");
  e.kind = bytes.substr(kHeaderBytes + 4, kind_bytes);
  e.payload_offset = kHeaderBytes + 4 + kind_bytes;
  e.payload_size = body - 4 - kind_bytes;
  if (has_signature) {
    const std::size_t at = e.body_end;
    if (bytes.compare(at, kSignatureMagic.size(), kSignatureMagic) != 0) refuse(name, "damaged signature block");
    PublicKeyBytes key;
    SignatureBytes sig;
    std::memcpy(key.data(), bytes.data() + at + 8, key.size());
    std::memcpy(sig.data(), bytes.data() + at + 8 + key.size(), sig.size());
    if (!verifySignature(key, signedMessage(bytes), sig))
      refuse(name, "signature does not verify (file corrupted or tampered with; key " + keyFingerprint(key) + ")");
    e.signer = key;
  }
  if (has_release) {
    const std::size_t at = e.body_end;
    if (bytes.compare(at, kReleaseSignatureMagic.size(), kReleaseSignatureMagic) != 0) refuse(name, "damaged signature block");
    PublicKeyBytes key;
    SignatureBytes sig;
    SignedRelease release;
    std::memcpy(key.data(), bytes.data() + at + 8, key.size());
    release.version = podAt<std::uint64_t>(bytes, at + 8 + key.size());
    release.signed_unix_s = podAt<std::int64_t>(bytes, at + 8 + key.size() + 8);
    std::memcpy(sig.data(), bytes.data() + at + 8 + key.size() + 16, sig.size());
    if (!verifySignature(key, releaseSignedMessage(bytes, release), sig))
      refuse(name, "signature does not verify (file corrupted or tampered with; key " + keyFingerprint(key) + ")");
    e.signer = key;
    e.release = release;
  }
  return e;
}

std::string readWholeFile(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) refuse(path, "cannot read (" + ec.message() + ")");
  if (size > kMaxFileBytes) refuse(path, "too large for a masa file (" + std::to_string(size) + " bytes)");
  std::ifstream in(path, std::ios::binary);
  if (!in) refuse(path, "cannot open");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (in.gcount() != static_cast<std::streamsize>(bytes.size())) refuse(path, "changed size while read");
  return bytes;
}

// The body's start: the kind's length and name, before the payload.
std::string kindPrefix(const FileKind& kind) {
  std::string out;
  appendPod(out, static_cast<std::uint32_t>(kind.name.size()));
  out.append(kind.name);
  return out;
}

// The seal's header for a body of `body_bytes` bytes whose SHA-256 is `digest`.
std::string sealHeader(std::uint64_t body_bytes, const Digest& digest) {
  std::string out;
  out.reserve(kHeaderBytes);
  out.append(kSealMagic);
  appendPod(out, kEnvelopeVersion);
  appendPod(out, body_bytes);
  out.append(reinterpret_cast<const char*>(digest.data()), digest.size());
  return out;
}

// The temporary file beside `path` that becomes it once whole.
std::string temporaryFor(const std::string& path) { return path + ".tmp"; }

std::FILE* openTemporary(const std::string& tmp) {
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) refuse(tmp, std::string("cannot write (") + std::strerror(errno) + ")");
  return f;
}

// Flushed to the disk, closed and renamed over `path`: a reader sees the old file or the new one,
// never half of one, even after a crash. `ok` false (a write failed) removes the temporary instead.
void publishTemporary(std::FILE* f, const std::string& tmp, const std::string& path, bool ok) {
  ok = ok && std::fflush(f) == 0 && ::fsync(fileno(f)) == 0;
  if (std::fclose(f) != 0 || !ok) {
    std::remove(tmp.c_str());
    refuse(tmp, "write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) refuse(path, "cannot rename " + tmp + " to it (" + ec.message() + ")");
}

void writeAtomically(const std::string& path, std::string_view bytes) {
  const std::string tmp = temporaryFor(path);
  std::FILE* f = openTemporary(tmp);
  publishTemporary(f, tmp, path, std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size());
}

// A sealed file's body on its way to the disk: each byte is hashed and written as it comes, through
// one buffer of its own, so the payload is never whole in memory.
class HashingFileBuf final : public std::streambuf {
 public:
  explicit HashingFileBuf(std::FILE* f) : f_(f), buf_(kBufferBytes) { resetBuffer(); }

  std::uint64_t bytes() const { return emitted_ + static_cast<std::uint64_t>(pptr() - pbase()); }
  // Writes out what is buffered; false once the disk refused a byte.
  bool drain() {
    emit(pbase(), pptr() - pbase());
    resetBuffer();
    return !failed_;
  }
  Digest digest() { return sha_.finish(); }

 protected:
  int_type overflow(int_type ch) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(ch, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(ch);
      pbump(1);
    }
    return traits_type::not_eof(ch);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    if (n > epptr() - pptr()) {
      if (!drain()) return 0;
      if (n > epptr() - pptr()) {  // larger than the buffer: straight to the disk, no copy
        emit(s, n);
        return failed_ ? 0 : n;
      }
    }
    std::memcpy(pptr(), s, static_cast<std::size_t>(n));
    pbump(static_cast<int>(n));
    return n;
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  static constexpr std::size_t kBufferBytes = std::size_t{1} << 20;

  void resetBuffer() { setp(buf_.data(), buf_.data() + buf_.size()); }
  void emit(const char* p, std::streamsize n) {
    if (n <= 0 || failed_) return;
    sha_.update(p, static_cast<std::size_t>(n));
    emitted_ += static_cast<std::uint64_t>(n);
    failed_ = std::fwrite(p, 1, static_cast<std::size_t>(n), f_) != static_cast<std::size_t>(n);
  }

  std::FILE* f_;
  std::vector<char> buf_;
  Sha256 sha_;
  std::uint64_t emitted_ = 0;
  bool failed_ = false;
};

}  // namespace

std::string OpenedFile::describe() const {
  if (!sealed) return "unsealed (written before masa sealed its files: not checked)";
  if (!signer) return "sealed (SHA-256 checked), unsigned";
  std::string out = "sealed (SHA-256 checked), signed by " + keyFingerprint(*signer);
  if (release) out += " as release " + std::to_string(release->version);
  return out;
}

std::string sealBytes(const FileKind& kind, std::string_view payload) {
  std::string body = kindPrefix(kind);
  body.append(payload);
  return sealHeader(body.size(), sha256(body)).append(body);
}

void writeSealedFile(const std::string& path, const FileKind& kind, std::string_view payload) {
  writeSealedFileStreamed(path, kind, [&](std::ostream& os) { os.write(payload.data(), static_cast<std::streamsize>(payload.size())); });
}

void writeSealedFileStreamed(const std::string& path, const FileKind& kind, const std::function<void(std::ostream&)>& write_payload) {
  const std::string tmp = temporaryFor(path);
  std::FILE* f = openTemporary(tmp);
  bool ok = false;
  try {
    // The header's length and checksum are known only at the end: room for it now, filled in then.
    const char room[kHeaderBytes] = {};
    ok = std::fwrite(room, 1, kHeaderBytes, f) == kHeaderBytes;
    HashingFileBuf body(f);
    std::ostream os(&body);
    const std::string prefix = kindPrefix(kind);
    os.write(prefix.data(), static_cast<std::streamsize>(prefix.size()));
    write_payload(os);
    ok = ok && os.good() && body.drain();
    const std::string header = sealHeader(body.bytes(), body.digest());
    ok = ok && std::fseek(f, 0, SEEK_SET) == 0 && std::fwrite(header.data(), 1, header.size(), f) == header.size();
  } catch (...) {
    std::fclose(f);
    std::remove(tmp.c_str());
    throw;
  }
  publishTemporary(f, tmp, path, ok);
}

OpenedFile openSealedBytes(std::string bytes, const std::string& name, const FileKind& kind, const ReadRules& rules) {
  OpenedFile out;
  if (std::string_view(bytes).substr(0, kSealMagic.size()) != kSealMagic) {
    if (kind.legacy_magic.empty() || std::string_view(bytes).substr(0, kind.legacy_magic.size()) != kind.legacy_magic)
      refuse(name, "not a " + std::string(kind.name) + " file (no seal, and not the format's own start)");
    if (rules.require_signed_by)
      refuse(name, "not signed (written before masa sealed its files; masa_seal add, then masa_seal sign)");
    if (rules.warn_unsealed)
      std::fprintf(stderr, "masa: warning: %s: written before masa sealed its files, so no checksum proves it intact (masa_seal add %s seals it)\n",
                   name.c_str(), name.c_str());
    out.payload = std::move(bytes);
    return out;
  }
  const Envelope e = checkEnvelope(bytes, name);
  if (e.kind != kind.name) refuse(name, "a " + e.kind + " file, not a " + std::string(kind.name) + " file");
  if (rules.require_signed_by) {
    if (!e.signer) refuse(name, "not signed, and a signature by a trusted key is required (masa_seal sign)");
    if (!rules.require_signed_by->contains(*e.signer))
      refuse(name, "signed by " + keyFingerprint(*e.signer) + ", which is not a trusted key (" + rules.require_signed_by->source() + ")");
  }
  if (rules.min_release_version > 0) {
    // A release version is believed only as signed by a trusted key: anyone can sign their own.
    if (!rules.require_signed_by) refuse(name, "a minimum release version needs the trusted keys that sign releases");
    const std::string wanted = "release " + std::to_string(rules.min_release_version) + " or newer is required";
    if (!e.release) refuse(name, "its signature names no release version, and " + wanted + " (masa_seal sign --release-version)");
    if (e.release->version < rules.min_release_version)
      refuse(name, "release " + std::to_string(e.release->version) + ", older than the newest accepted: " + wanted);
  }
  out.sealed = true;
  out.signer = e.signer;
  out.release = e.release;
  out.payload = bytes.substr(e.payload_offset, e.payload_size);
  return out;
}

OpenedFile readSealedFile(const std::string& path, const FileKind& kind, const ReadRules& rules) {
  return openSealedBytes(readWholeFile(path), path, kind, rules);
}

std::string sealedKindOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(kHeaderBytes + 4 + kMaxKindBytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.size() < kHeaderBytes + 4 || head.compare(0, kSealMagic.size(), kSealMagic) != 0) return "";
  const auto n = podAt<std::uint32_t>(head, kHeaderBytes);
  if (n > kMaxKindBytes || kHeaderBytes + 4 + n > head.size()) return "";
  return head.substr(kHeaderBytes + 4, n);
}

bool looksLikeKind(const std::string& path, const FileKind& kind) {
  if (sealedKindOf(path) == kind.name) return true;
  std::ifstream in(path, std::ios::binary);
  std::string head(kind.legacy_magic.size(), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  return in && !kind.legacy_magic.empty() && head == kind.legacy_magic;
}

void signSealedFile(const std::string& path, const SigningKey& key, const std::optional<SignedRelease>& release) {
  std::string bytes = readWholeFile(path);
  if (std::string_view(bytes).substr(0, kSealMagic.size()) != kSealMagic)
    refuse(path, "not sealed, so it cannot be signed (masa_seal add seals it)");
  const Envelope e = checkEnvelope(bytes, path);
  bytes.resize(e.body_end);  // any earlier signature goes
  const SignatureBytes sig = key.sign(release ? releaseSignedMessage(bytes, *release) : signedMessage(bytes));
  const PublicKeyBytes pub = key.publicKey();
  bytes.append(release ? kReleaseSignatureMagic : kSignatureMagic);
  bytes.append(reinterpret_cast<const char*>(pub.data()), pub.size());
  if (release) {
    appendPod(bytes, release->version);
    appendPod(bytes, release->signed_unix_s);
  }
  bytes.append(reinterpret_cast<const char*>(sig.data()), sig.size());
  writeAtomically(path, bytes);
}

}  // namespace masa::integrity
