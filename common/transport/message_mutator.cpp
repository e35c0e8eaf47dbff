#include "common/transport/message_mutator.hpp"

#include <iterator>
#include <utility>

namespace masa::transport {

namespace {
void putBigEndian32(std::vector<uint8_t>& b, std::size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = static_cast<uint8_t>(v >> (24 - 8 * i));
}
}  // namespace

MessageMutator::MessageMutator(std::vector<uint8_t> valid, uint64_t seed) : valid_(std::move(valid)), rng_(seed) {
  // The length fields (and a few other integers) are the small non-negative int32 values.
  for (std::size_t o = 8; o + 4 <= valid_.size(); ++o) {
    const uint32_t v = (uint32_t(valid_[o]) << 24) | (uint32_t(valid_[o + 1]) << 16) | (uint32_t(valid_[o + 2]) << 8) |
                       uint32_t(valid_[o + 3]);
    if (v <= 4096) length_like_.push_back(o);
  }
}

std::vector<uint8_t> MessageMutator::next() {
  std::vector<uint8_t> m = valid_;
  const int ops = 1 + static_cast<int>(rng_() % 3);
  for (int k = 0; k < ops; ++k) {
    switch (rng_() % 6) {
      case 0: {  // bit flips
        const int flips = 1 + static_cast<int>(rng_() % 4);
        for (int f = 0; f < flips && !m.empty(); ++f) m[rng_() % m.size()] ^= static_cast<uint8_t>(1u << (rng_() % 8));
        break;
      }
      case 1:  // a length field overwritten
        if (!length_like_.empty()) {
          const std::size_t o = length_like_[rng_() % length_like_.size()];
          if (o + 4 <= m.size()) putBigEndian32(m, o, interesting(m.size()));
        }
        break;
      case 2:  // any 4 bytes overwritten
        if (m.size() >= 4) putBigEndian32(m, rng_() % (m.size() - 3), interesting(m.size()));
        break;
      case 3:  // truncation
        m.resize(m.empty() ? 0 : rng_() % m.size());
        break;
      case 4: {  // extension
        const int extra = 1 + static_cast<int>(rng_() % 16);
        for (int i = 0; i < extra; ++i) m.push_back(static_cast<uint8_t>(rng_()));
        break;
      }
      case 5: {  // insertion or deletion inside
        if (m.empty()) break;
        const std::size_t at = rng_() % m.size();
        if (rng_() % 2) {
          m.insert(m.begin() + static_cast<std::ptrdiff_t>(at), static_cast<uint8_t>(rng_()));
        } else {
          m.erase(m.begin() + static_cast<std::ptrdiff_t>(at));
        }
        break;
      }
    }
  }
  return m;
}

uint32_t MessageMutator::interesting(std::size_t size) {
  const uint32_t values[] = {0u,          1u,          0xffffffffu, 2u,
                             0x7f7fffffu, 0x7fffffffu, 0x80000000u, 0x20000000u,
                             0x40000000u, 0x10000000u, static_cast<uint32_t>(size),
                             static_cast<uint32_t>(size / 4), static_cast<uint32_t>(size / 4 + 1),
                             static_cast<uint32_t>(size / 8), static_cast<uint32_t>(rng_())};
  return values[rng_() % std::size(values)];
}

}  // namespace masa::transport
