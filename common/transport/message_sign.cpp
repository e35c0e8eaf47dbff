#include "common/transport/message_sign.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include <openssl/evp.h>

#include "common/transport/transport.hpp"

namespace masa::transport {

namespace {

constexpr char kDomain[] = "MASA-SIG1";  // 9 bytes, without the NUL
constexpr int kDomainBytes = sizeof kDomain - 1;
constexpr int kDigestBytes = 32;
constexpr int kSignedBytes = kDomainBytes + kDigestBytes;

void putBigEndian(uint8_t* p, uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i, v >>= 8) p[i] = static_cast<uint8_t>(v & 0xff);
}

uint64_t getBigEndian(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = v << 8 | p[i];
  return v;
}

void writeHeader(uint8_t* header, SenderId id, uint64_t counter) {
  std::memcpy(header, kSigMarker, kSigMarkerBytes);
  header[kSigMarkerBytes] = static_cast<uint8_t>(id.role);
  putBigEndian(header + kSigMarkerBytes + 1, id.index, 4);
  putBigEndian(header + kSigMarkerBytes + 5, counter, 8);
}

// What the Ed25519 signature is over: the domain and the SHA-256 of domain, channel, separator,
// header (role, index, counter) and message.
void signedBytes(std::string_view channel, const uint8_t* header, const void* message, int size, uint8_t* out) {
  std::memcpy(out, kDomain, kDomainBytes);
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
  const uint8_t separator = 0;
  unsigned int n = 0;
  const bool ok = ctx != nullptr && EVP_DigestInit_ex(ctx, EVP_sha256(), nullptr) == 1 &&
                  EVP_DigestUpdate(ctx, kDomain, kDomainBytes) == 1 &&
                  EVP_DigestUpdate(ctx, channel.data(), channel.size()) == 1 && EVP_DigestUpdate(ctx, &separator, 1) == 1 &&
                  EVP_DigestUpdate(ctx, header + kSigMarkerBytes, kSigHeaderBytes - kSigMarkerBytes) == 1 &&
                  EVP_DigestUpdate(ctx, message, static_cast<std::size_t>(size)) == 1 &&
                  EVP_DigestFinal_ex(ctx, out + kDomainBytes, &n) == 1 && n == kDigestBytes;
  EVP_MD_CTX_free(ctx);
  if (!ok) throw std::runtime_error("message signing: SHA-256 failed");
}

bool verifyWith(void* pkey, const uint8_t* signed_bytes, const uint8_t* signature) {
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
  const bool ok = ctx != nullptr &&
                  EVP_DigestVerifyInit(ctx, nullptr, nullptr, nullptr, static_cast<EVP_PKEY*>(pkey)) == 1 &&
                  EVP_DigestVerify(ctx, signature, kSigBytes, signed_bytes, kSignedBytes) == 1;
  EVP_MD_CTX_free(ctx);
  return ok;
}

}  // namespace

int64_t maxSignedMessageBytes(Role role) {
  return role == Role::kRobot || role == Role::kRunner ? int64_t{64} << 10 : int64_t{64} << 20;
}

MessageSigner::MessageSigner(integrity::SigningKey key, SenderId id, uint64_t first_counter)
    : key_(std::move(key)),
      public_(key_.publicKey()),
      id_(id),
      next_(first_counter) {}

std::shared_ptr<MessageSigner> MessageSigner::load(const std::string& key_path, SenderId id, const Roster& roster) {
  integrity::SigningKey key = integrity::SigningKey::load(key_path);
  const Roster::Entry* entry = roster.find(id);
  if (entry == nullptr)
    throw std::runtime_error("signing key " + key_path + ": the roster " + roster.source() + " lists no " + id.name());
  if (entry->key != key.publicKey())
    throw std::runtime_error("signing key " + key_path + " (" + integrity::keyFingerprint(key.publicKey()) +
                             ") is not the key the roster " + roster.source() + " gives " + id.name() + " (" +
                             integrity::keyFingerprint(entry->key) + ")");
  return std::make_shared<MessageSigner>(std::move(key), id);
}

void MessageSigner::seal(std::string_view channel, const void* message, int size, uint8_t* trailer) {
  // The clock, unless a message of this process already took that microsecond (or the clock stepped back).
  const uint64_t now = static_cast<uint64_t>(std::max<int64_t>(0, wallClockMicros()));
  uint64_t next = next_.load();
  uint64_t counter = 0;
  do counter = std::max(next, now);
  while (!next_.compare_exchange_weak(next, counter + 1));
  sealWithCounter(channel, message, size, counter, trailer);
}

void MessageSigner::sealWithCounter(std::string_view channel, const void* message, int size, uint64_t counter,
                                    uint8_t* trailer) const {
  writeHeader(trailer, id_, counter);
  uint8_t to_sign[kSignedBytes];
  signedBytes(channel, trailer, message, size, to_sign);
  const integrity::SignatureBytes sig =
      key_.sign(std::string_view(reinterpret_cast<const char*>(to_sign), kSignedBytes));
  std::memcpy(trailer + kSigHeaderBytes, sig.data(), kSigBytes);
}

WireVerdict ReplayWindow::check(uint64_t counter) const {
  if (!any_ || counter > top_) return WireVerdict::kOk;
  const uint64_t below = top_ - counter;
  if (below >= static_cast<uint64_t>(kReplayWindow)) return WireVerdict::kBeyondWindow;
  return seen_.test(static_cast<std::size_t>(below)) ? WireVerdict::kReplayed : WireVerdict::kOk;
}

void ReplayWindow::accept(uint64_t counter) {
  if (!any_ || counter > top_) {
    const uint64_t shift = any_ ? counter - top_ : static_cast<uint64_t>(kReplayWindow);
    if (shift >= static_cast<uint64_t>(kReplayWindow)) seen_.reset();
    else seen_ <<= static_cast<std::size_t>(shift);
    top_ = counter;
    any_ = true;
    seen_.set(0);
    return;
  }
  const uint64_t below = top_ - counter;
  if (below < static_cast<uint64_t>(kReplayWindow)) seen_.set(static_cast<std::size_t>(below));
}

MessageVerifier::MessageVerifier(std::shared_ptr<const Roster> roster, uint64_t not_before_us)
    : roster_(std::move(roster)), not_before_us_(not_before_us) {
  if (!roster_) throw std::invalid_argument("message verifier: no roster");
}

OpenedMessage MessageVerifier::open(std::string_view channel, const void* data, int size) const {
  OpenedMessage m;
  const auto* p = static_cast<const uint8_t*>(data);
  if (p == nullptr || size < kSigTrailerBytes) return m;
  const uint8_t* trailer = p + size - kSigTrailerBytes;
  if (std::memcmp(trailer, kSigMarker, kSigMarkerBytes) != 0 || !isRole(trailer[kSigMarkerBytes])) return m;
  m.sender.role = static_cast<Role>(trailer[kSigMarkerBytes]);
  m.sender.index = static_cast<uint32_t>(getBigEndian(trailer + kSigMarkerBytes + 1, 4));
  m.counter = getBigEndian(trailer + kSigMarkerBytes + 5, 8);
  const Roster::Entry* entry = roster_->find(m.sender);
  if (entry == nullptr) {
    m.verdict = WireVerdict::kUnknownSender;
    return m;
  }
  if (!Roster::permits(*entry, channel)) {
    m.verdict = WireVerdict::kNotPermitted;
    return m;
  }
  const int message_size = size - kSigTrailerBytes;
  if (message_size > maxSignedMessageBytes(m.sender.role)) {
    m.verdict = WireVerdict::kOverLimit;
    return m;
  }
  ++messages_hashed_;
  uint8_t to_check[kSignedBytes];
  signedBytes(channel, trailer, p, message_size, to_check);
  if (!verifyWith(entry->verifier.get(), to_check, trailer + kSigHeaderBytes)) {
    m.verdict = WireVerdict::kUnauthenticated;
    return m;
  }
  m.verdict = WireVerdict::kOk;
  m.size = message_size;
  return m;
}

WireVerdict MessageVerifier::fresh(std::string_view channel, const OpenedMessage& m) const {
  if (m.counter < not_before_us_) return WireVerdict::kBeforeStart;
  const auto it = windows_.find({m.sender, std::string(channel)});
  return it == windows_.end() ? WireVerdict::kOk : it->second.check(m.counter);
}

void MessageVerifier::accept(std::string_view channel, const OpenedMessage& m) {
  windows_[{m.sender, std::string(channel)}].accept(m.counter);
}

bool peekSigner(const void* data, int size, SenderId& sender, uint64_t& counter) {
  const auto* p = static_cast<const uint8_t*>(data);
  if (p == nullptr || size < kSigTrailerBytes) return false;
  const uint8_t* trailer = p + size - kSigTrailerBytes;
  if (std::memcmp(trailer, kSigMarker, kSigMarkerBytes) != 0 || !isRole(trailer[kSigMarkerBytes])) return false;
  sender.role = static_cast<Role>(trailer[kSigMarkerBytes]);
  sender.index = static_cast<uint32_t>(getBigEndian(trailer + kSigMarkerBytes + 1, 4));
  counter = getBigEndian(trailer + kSigMarkerBytes + 5, 8);
  return true;
}

}  // namespace masa::transport
