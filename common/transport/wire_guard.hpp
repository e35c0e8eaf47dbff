// The one gate every received LCM message passes before lcm-gen's decoder runs.
//
// lcm-gen's C++ decoder trusts the length fields it reads: it resizes each array to its length
// before checking that the bytes are there, and computes the byte count as `4 * n` in an int, so a
// 77-byte MASA_POLICY message with num_params = 0x7f7fffff overflows it and reads past the buffer.
// The guard walks the message by its WireLayoutOf table, reading only hash, scalar length fields
// and string lengths, and accepts it only when every array and string fits in the bytes that are
// left, stays under sane maxima, every string is one NUL-terminated C string (what the encoder
// writes, so an accepted message re-encodes to the same bytes), and the message ends exactly at
// the end of the buffer. decodeChecked() is guard + decode: the only way masa decodes a message.
#pragma once

#include <array>
#include <cstdint>
#include <exception>
#include <span>
#include <string_view>
#include <vector>

#include "common/transport/wire_layout.hpp"

namespace masa::transport {

// Why a message was rejected before (or by) the decoder. Stable snake_case names for counters.
enum class WireVerdict : int {
  kOk = 0,
  kWrongType,       // the 8-byte hash is not the channel's type
  kTruncated,       // a field, array or string runs past the end of the bytes
  kTrailingBytes,   // bytes left after the last field
  kNegativeLength,  // an array or string length below zero
  kOverLimit,       // an array or string longer than WireLimits allows, or a signed message longer than
                    // its sender's role sends (maxSignedMessageBytes, message_sign.hpp), refused unhashed
  kBadString,       // a string without its terminating NUL, with a NUL inside, or of length 0
  kDecodeFailed,    // the guard passed but lcm-gen's decoder did not consume exactly the bytes
  kUnauthenticated, // no trailer of the run key that verifies (Transport with a key, message_auth.hpp), or
                    // no SIG1 trailer whose signature verifies (Transport with a signer, message_sign.hpp)
  // Signed runs (message_sign.hpp):
  kUnknownSender,        // the trailer names a sender the run's roster does not list
  kNotPermitted,         // the roster does not let that sender publish on this channel
  kClaimsAnotherSender,  // signed by one actor, claiming another's actor id
  kReplayed,             // its counter was taken before from this sender on this channel
  kBeyondWindow,         // its counter is more than kReplayWindow below the sender's newest
  kBeforeStart,          // its counter (the sender's clock when it signed) is older than this receiver's start
  kAnotherRanksActor,    // a rollout chunk of an actor that reports to another learner rank of the MPI job
  kCount
};
inline constexpr int kNumWireVerdicts = static_cast<int>(WireVerdict::kCount);
std::string_view wireVerdictName(WireVerdict v);

// Messages rejected on one channel, per WireVerdict (the kOk entry stays 0).
using WireRejects = std::array<int64_t, kNumWireVerdicts>;

// Sane maxima, far above what masa sends (the largest policy is about 10^5 floats, names are short)
// and low enough that no length can make a decoder allocate more than a few hundred MB.
struct WireLimits {
  int64_t max_array_elements = int64_t{1} << 24;
  int64_t max_string_bytes = 4096;  // including the NUL
};

// A WireLayoutOf table with every array's length field resolved to its position.
class WireGuard {
 public:
  // Throws std::logic_error when the table is inconsistent (a length naming no earlier integer
  // field): a programming error, found the first time the type is used.
  WireGuard(int64_t hash, std::span<const WireField> fields);

  WireVerdict check(const void* data, int size, const WireLimits& limits = {}) const;

 private:
  struct Step {
    WireType type;
    int bytes;         // per element; 0 for a string
    int length_from;   // index of the field holding the element count; -1 for one value
    bool keep_value;   // an integer that is some array's length
  };
  int64_t hash_;
  std::vector<Step> steps_;
};

template <class Msg>
const WireGuard& wireGuardOf() {
  static const WireGuard guard(Msg::getHash(), WireLayoutOf<Msg>::fields);
  return guard;
}

template <class Msg>
WireVerdict checkWire(const void* data, int size, const WireLimits& limits = {}) {
  return wireGuardOf<Msg>().check(data, size, limits);
}

// Guard, then lcm-gen's decode into `msg`. A zero-length array is left as it was by the decoder:
// pass a fresh message, or clear its arrays first.
template <class Msg>
WireVerdict decodeChecked(const void* data, int size, Msg& msg, const WireLimits& limits = {}) {
  const WireVerdict v = checkWire<Msg>(data, size, limits);
  if (v != WireVerdict::kOk) return v;
  int used = -1;
  try {
    used = msg.decode(data, 0, size);
  } catch (const std::exception&) {  // cannot happen after the guard; never let it escape a handler
    used = -1;
  }
  return used == size ? WireVerdict::kOk : WireVerdict::kDecodeFailed;
}

}  // namespace masa::transport
