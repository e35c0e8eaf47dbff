// Random damage to a file's bytes, for the file readers' fuzz tests: what disks, copies and
// transfers do to files (bit flips, a cut, a field overwritten, a NaN written over a value, bytes
// spliced in from elsewhere in the file, bytes inserted or dropped). The generator is passed in,
// so that a failing case repeats from its seed; `what` names the mutation for the failure message.
#pragma once

#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <string>

namespace masa::fuzz {

struct FileMutation {
  std::string bytes;
  std::string what;
};

inline FileMutation mutateFile(const std::string& original, std::mt19937_64& rng) {
  FileMutation m{original, ""};
  std::string& b = m.bytes;
  if (b.empty()) return m;
  auto pick = [&](std::size_t n) { return static_cast<std::size_t>(rng() % n); };
  const std::size_t at = pick(b.size());
  switch (rng() % 8) {
    case 0: {
      const int flips = 1 + static_cast<int>(rng() % 3);
      for (int i = 0; i < flips; ++i) b[pick(b.size())] ^= static_cast<char>(1u << (rng() % 8));
      m.what = std::to_string(flips) + " bit flip(s)";
      break;
    }
    case 1:
      b.resize(at);
      m.what = "truncated to " + std::to_string(at) + " bytes";
      break;
    case 2: {
      const std::size_t width = std::size_t{1} << (rng() % 4);  // a 1, 2, 4 or 8 byte field
      for (std::size_t i = at; i < std::min(b.size(), at + width); ++i) b[i] = static_cast<char>(rng());
      m.what = std::to_string(width) + " random bytes at " + std::to_string(at);
      break;
    }
    case 3: {
      const float nan = std::numeric_limits<float>::quiet_NaN();
      const std::size_t aligned = at & ~std::size_t{3};
      if (aligned + sizeof nan <= b.size()) std::memcpy(b.data() + aligned, &nan, sizeof nan);
      m.what = "NaN at " + std::to_string(aligned);
      break;
    }
    case 4: {
      const std::size_t from = pick(b.size()), n = 1 + pick(std::min<std::size_t>(64, b.size()));
      const std::size_t len = std::min({n, b.size() - from, b.size() - at});
      std::memmove(b.data() + at, original.data() + from, len);
      m.what = std::to_string(len) + " bytes from " + std::to_string(from) + " spliced at " + std::to_string(at);
      break;
    }
    case 5: {
      const std::size_t n = 1 + pick(16);
      std::string extra(n, '\0');
      for (char& c : extra) c = static_cast<char>(rng());
      b.insert(at, extra);
      m.what = std::to_string(n) + " bytes inserted at " + std::to_string(at);
      break;
    }
    case 6: {
      const std::size_t n = 1 + pick(std::min<std::size_t>(16, b.size() - at));
      b.erase(at, n);
      m.what = std::to_string(n) + " bytes dropped at " + std::to_string(at);
      break;
    }
    default: {
      const std::size_t n = std::min<std::size_t>(1 + pick(32), b.size() - at);
      std::memset(b.data() + at, 0, n);
      m.what = std::to_string(n) + " bytes zeroed at " + std::to_string(at);
      break;
    }
  }
  return m;
}

// Flips bit (at % 8) of byte `at` of a file in place; a second call flips it back. Cheaper than
// rewriting the file, for the tests that flip every byte of one.
inline void flipBitInFile(const std::string& path, std::size_t at) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(static_cast<std::streamoff>(at));
  const char c = static_cast<char>(f.get() ^ (1 << (at % 8)));
  f.seekp(static_cast<std::streamoff>(at));
  f.put(c);
}

}  // namespace masa::fuzz
