// Message authentication: with a run key (run_key.hpp), every message on the wire ends in a trailer
// after its LCM-encoded bytes,
//
//   [encoded message] ["MAC1"] [HMAC-SHA256(key, channel || 0x00 || encoded message), 32 bytes]
//
// The trailer follows the last field, so lcm-gen's decoders, lcm-spy's included, read every field
// and stop before it; masa's receivers (Transport) check it before anything else sees the bytes and
// hand on the message without it. The channel is inside the MAC: a message and its tag copied to
// another channel do not verify. Freshness is not: a message recorded off the LAN verifies again
// when replayed within the run (docs/reliability.md says what stops replays).
#pragma once

#include <cstdint>
#include <string_view>

#include "common/transport/run_key.hpp"

struct evp_mac_ctx_st;

namespace masa::transport {

// The marker tells a sealed message from an unsigned one without the key (masa_lcm_probe), and
// names the trailer's format.
inline constexpr uint8_t kAuthMarker[4] = {'M', 'A', 'C', '1'};
inline constexpr int kAuthMarkerBytes = 4;
inline constexpr int kAuthTagBytes = 32;
inline constexpr int kAuthTrailerBytes = kAuthMarkerBytes + kAuthTagBytes;

// Thread-safe: each call works on its own copy of a context keyed once at construction.
class MessageAuthenticator {
 public:
  // Throws std::runtime_error when OpenSSL cannot set up HMAC-SHA256.
  explicit MessageAuthenticator(const RunKey& key);
  ~MessageAuthenticator();
  MessageAuthenticator(const MessageAuthenticator&) = delete;
  MessageAuthenticator& operator=(const MessageAuthenticator&) = delete;

  // Writes the trailer of the `size` bytes at `message`, sent on `channel`, to
  // trailer[0, kAuthTrailerBytes).
  void seal(std::string_view channel, const void* message, int size, uint8_t* trailer) const;
  // The size of the message before its trailer when `data` ends in a trailer that verifies for
  // `channel` (tags compared in constant time); -1 otherwise: too short, unsigned, or a wrong tag.
  int open(std::string_view channel, const void* data, int size) const;

 private:
  void tag(std::string_view channel, const void* message, int size, uint8_t* out) const;
  evp_mac_ctx_st* keyed_;  // HMAC-SHA256 with the key set: copied for each message
};

// Without the key: `size` less the trailer (MAC1, or a signed run's SIG1, message_sign.hpp) when
// `data` ends in one, else `size`, unverified. For
// tools that watch a run's traffic (masa_lcm_probe); never for bytes a process acts on.
int sizeBeforeTrailer(const void* data, int size);

}  // namespace masa::transport
