#include "common/transport/message_auth.hpp"

#include "common/transport/message_sign.hpp"

#include <cstring>
#include <stdexcept>

#include <openssl/core_names.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>

namespace masa::transport {

namespace {

bool hasMarker(const uint8_t* p, int size) {
  return size >= kAuthTrailerBytes && std::memcmp(p + size - kAuthTrailerBytes, kAuthMarker, kAuthMarkerBytes) == 0;
}

}  // namespace

MessageAuthenticator::MessageAuthenticator(const RunKey& key) {
  EVP_MAC* mac = EVP_MAC_fetch(nullptr, "HMAC", nullptr);
  keyed_ = mac ? EVP_MAC_CTX_new(mac) : nullptr;
  EVP_MAC_free(mac);  // the context holds its own reference
  char digest[] = "SHA256";
  const OSSL_PARAM params[] = {OSSL_PARAM_construct_utf8_string(OSSL_MAC_PARAM_DIGEST, digest, 0), OSSL_PARAM_construct_end()};
  if (keyed_ == nullptr || EVP_MAC_init(keyed_, key.bytes.data(), key.bytes.size(), params) != 1) {
    EVP_MAC_CTX_free(keyed_);
    throw std::runtime_error("message authentication: OpenSSL cannot set up HMAC-SHA256");
  }
}

MessageAuthenticator::~MessageAuthenticator() { EVP_MAC_CTX_free(keyed_); }

void MessageAuthenticator::tag(std::string_view channel, const void* message, int size, uint8_t* out) const {
  // A copy keeps the keyed context untouched (and the key's pads already hashed), so concurrent
  // calls and every later message start from the same state.
  EVP_MAC_CTX* ctx = EVP_MAC_CTX_dup(keyed_);
  const uint8_t separator = 0;  // channel names hold no NUL: channel and message cannot run together
  std::size_t n = 0;
  const bool ok = ctx != nullptr && EVP_MAC_update(ctx, reinterpret_cast<const uint8_t*>(channel.data()), channel.size()) == 1 &&
                  EVP_MAC_update(ctx, &separator, 1) == 1 &&
                  EVP_MAC_update(ctx, static_cast<const uint8_t*>(message), static_cast<std::size_t>(size)) == 1 &&
                  EVP_MAC_final(ctx, out, &n, kAuthTagBytes) == 1 && n == kAuthTagBytes;
  EVP_MAC_CTX_free(ctx);
  if (!ok) throw std::runtime_error("message authentication: HMAC-SHA256 failed");
}

void MessageAuthenticator::seal(std::string_view channel, const void* message, int size, uint8_t* trailer) const {
  std::memcpy(trailer, kAuthMarker, kAuthMarkerBytes);
  tag(channel, message, size, trailer + kAuthMarkerBytes);
}

int MessageAuthenticator::open(std::string_view channel, const void* data, int size) const {
  const auto* p = static_cast<const uint8_t*>(data);
  if (p == nullptr || !hasMarker(p, size)) return -1;
  const int message_size = size - kAuthTrailerBytes;
  uint8_t expected[kAuthTagBytes];
  tag(channel, p, message_size, expected);
  // Constant time: how many leading bytes matched must not show in the time a rejection takes.
  if (CRYPTO_memcmp(expected, p + size - kAuthTagBytes, kAuthTagBytes) != 0) return -1;
  return message_size;
}

int sizeBeforeTrailer(const void* data, int size) {
  if (data == nullptr) return size;
  if (hasMarker(static_cast<const uint8_t*>(data), size)) return size - kAuthTrailerBytes;
  SenderId sender;
  uint64_t counter = 0;
  return peekSigner(data, size, sender, counter) ? size - kSigTrailerBytes : size;  // a signed run's SIG1
}

}  // namespace masa::transport
