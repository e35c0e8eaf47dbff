#include "common/transport/wire_guard.hpp"

#include <cstring>
#include <stdexcept>
#include <string>

namespace masa::transport {

namespace {

int bytesOf(WireType t) {
  switch (t) {
    case WireType::kInt8:
    case WireType::kByte:
    case WireType::kBoolean: return 1;
    case WireType::kInt16: return 2;
    case WireType::kInt32:
    case WireType::kFloat: return 4;
    case WireType::kInt64:
    case WireType::kDouble: return 8;
    case WireType::kString: return 0;
  }
  return 0;
}

bool isInteger(WireType t) {
  return t == WireType::kInt8 || t == WireType::kInt16 || t == WireType::kInt32 || t == WireType::kInt64;
}

// Big-endian two's complement of `bytes` bytes, sign-extended.
int64_t readSigned(const uint8_t* p, int bytes) {
  uint64_t u = 0;
  for (int i = 0; i < bytes; ++i) u = (u << 8) | p[i];
  const int unused = 64 - 8 * bytes;
  return unused == 0 ? static_cast<int64_t>(u) : static_cast<int64_t>(u << unused) >> unused;
}

// Length fields read so far, by field index; masa's types have fewer fields than this.
constexpr int kMaxFields = 128;

}  // namespace

std::string_view wireVerdictName(WireVerdict v) {
  switch (v) {
    case WireVerdict::kOk: return "ok";
    case WireVerdict::kWrongType: return "wrong_type";
    case WireVerdict::kTruncated: return "truncated";
    case WireVerdict::kTrailingBytes: return "trailing_bytes";
    case WireVerdict::kNegativeLength: return "negative_length";
    case WireVerdict::kOverLimit: return "over_limit";
    case WireVerdict::kBadString: return "bad_string";
    case WireVerdict::kDecodeFailed: return "decode_failed";
    case WireVerdict::kUnauthenticated: return "unauthenticated";
    case WireVerdict::kUnknownSender: return "unknown_sender";
    case WireVerdict::kNotPermitted: return "not_permitted";
    case WireVerdict::kClaimsAnotherSender: return "claims_another_sender";
    case WireVerdict::kReplayed: return "replayed";
    case WireVerdict::kBeyondWindow: return "beyond_window";
    case WireVerdict::kBeforeStart: return "before_start";
    case WireVerdict::kAnotherRanksActor: return "another_ranks_actor";
    case WireVerdict::kCount: break;
  }
  return "unknown";
}

WireGuard::WireGuard(int64_t hash, std::span<const WireField> fields) : hash_(hash) {
  if (fields.size() > static_cast<std::size_t>(kMaxFields))
    throw std::logic_error("wire guard: more than " + std::to_string(kMaxFields) + " fields");
  for (std::size_t i = 0; i < fields.size(); ++i) {
    Step s{fields[i].type, bytesOf(fields[i].type), -1, false};
    if (!fields[i].length.empty()) {
      for (std::size_t j = 0; j < i; ++j)
        if (fields[j].name == fields[i].length && fields[j].length.empty() && isInteger(fields[j].type))
          s.length_from = static_cast<int>(j);
      if (s.length_from < 0)
        throw std::logic_error("wire guard: the length of '" + std::string(fields[i].name) + "', '" +
                               std::string(fields[i].length) + "', is no earlier integer field");
      steps_[s.length_from].keep_value = true;
    }
    steps_.push_back(s);
  }
}

WireVerdict WireGuard::check(const void* data, int size, const WireLimits& limits) const {
  if (data == nullptr || size < 8) return WireVerdict::kTruncated;
  const auto* p = static_cast<const uint8_t*>(data);
  if (readSigned(p, 8) != hash_) return WireVerdict::kWrongType;
  int64_t pos = 8;
  const int64_t end = size;
  int64_t values[kMaxFields];
  for (std::size_t i = 0; i < steps_.size(); ++i) {
    const Step& s = steps_[i];
    int64_t count = 1;
    if (s.length_from >= 0) {
      count = values[s.length_from];
      if (count < 0) return WireVerdict::kNegativeLength;
      if (count > limits.max_array_elements) return WireVerdict::kOverLimit;
    }
    if (s.type == WireType::kString) {
      for (int64_t k = 0; k < count; ++k) {
        if (end - pos < 4) return WireVerdict::kTruncated;
        const int64_t len = readSigned(p + pos, 4);  // bytes including the NUL
        pos += 4;
        if (len < 0) return WireVerdict::kNegativeLength;
        if (len == 0) return WireVerdict::kBadString;  // the decoder would take len - 1 = SIZE_MAX characters
        if (len > limits.max_string_bytes) return WireVerdict::kOverLimit;
        if (len > end - pos) return WireVerdict::kTruncated;
        if (p[pos + len - 1] != 0 || std::memchr(p + pos, 0, static_cast<std::size_t>(len - 1)) != nullptr)
          return WireVerdict::kBadString;
        pos += len;
      }
      continue;
    }
    const int64_t bytes = count * s.bytes;  // count <= 2^24: no overflow
    if (bytes > end - pos) return WireVerdict::kTruncated;
    if (s.keep_value) values[i] = readSigned(p + pos, s.bytes);
    pos += bytes;
  }
  return pos == end ? WireVerdict::kOk : WireVerdict::kTrailingBytes;
}

}  // namespace masa::transport
