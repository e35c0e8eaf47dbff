// SHA-256 through OpenSSL's libcrypto: the checksum every masa file carries (sealed_file.hpp) and
// the chain of a dataset log's seals (common/dataset/log_seal.hpp).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace masa::integrity {

using Digest = std::array<std::uint8_t, 32>;

// A digest built from pieces fed one after the other.
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;
  Sha256& update(const void* data, std::size_t n);
  Sha256& update(std::string_view bytes) { return update(bytes.data(), bytes.size()); }
  Digest finish();  // ends this digest; update() again starts nothing new

 private:
  struct Context;
  std::unique_ptr<Context> ctx_;
};

Digest sha256(std::string_view bytes);

// Lower-case hex, for messages and fingerprints.
std::string toHex(const std::uint8_t* bytes, std::size_t n);
inline std::string toHex(const Digest& d) { return toHex(d.data(), d.size()); }

}  // namespace masa::integrity
