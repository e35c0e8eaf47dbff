// Hostile copies of a valid encoded message, for fuzzing every decoder: bit flips, length-like
// fields overwritten with hostile values (0, -1, 0x7f7fffff, the size, ...), any 4 bytes
// overwritten, truncation, extension, and insertion or deletion inside; one to three at a time.
// Used by the unit fuzz test (tests/unit/test_hostile_messages.cpp) and by masa_lcm_fuzz, which
// republishes mutated copies of a live run's messages.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

namespace masa::transport {

class MessageMutator {
 public:
  // `valid` is a whole encoded message (type hash first); `seed` makes the sequence reproducible.
  MessageMutator(std::vector<uint8_t> valid, uint64_t seed);

  // The next mutated copy.
  std::vector<uint8_t> next();

 private:
  uint32_t interesting(std::size_t size);

  std::vector<uint8_t> valid_;
  std::vector<std::size_t> length_like_;  // offsets of small non-negative int32 values
  std::mt19937_64 rng_;
};

}  // namespace masa::transport
