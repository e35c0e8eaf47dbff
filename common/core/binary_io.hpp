// Fixed-size fields of masa's binary files (learner checkpoints, parameter files, Adam states, an
// actor's environments), written as they lie in memory: these files move between builds on the
// same kind of machine, not across byte orders. Writing leaves errors to the stream's state, which
// each format checks once; reading says whether the bytes were there, and each format throws its
// own message naming the file and the field it was reading.
#pragma once

#include <cstddef>
#include <istream>
#include <ostream>
#include <type_traits>

namespace masa::io {

template <class T>
void writePod(std::ostream& os, const T& v) {
  static_assert(std::is_trivially_copyable_v<T>, "only plain values are written as bytes");
  os.write(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <class T>
void writeArray(std::ostream& os, const T* data, std::size_t n) {
  static_assert(std::is_trivially_copyable_v<T>, "only plain values are written as bytes");
  os.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(n * sizeof(T)));
}

template <class T>
[[nodiscard]] bool readPod(std::istream& is, T& v) {
  static_assert(std::is_trivially_copyable_v<T>, "only plain values are read as bytes");
  return static_cast<bool>(is.read(reinterpret_cast<char*>(&v), sizeof(T)));
}

template <class T>
[[nodiscard]] bool readArray(std::istream& is, T* data, std::size_t n) {
  static_assert(std::is_trivially_copyable_v<T>, "only plain values are read as bytes");
  return static_cast<bool>(is.read(reinterpret_cast<char*>(data), static_cast<std::streamsize>(n * sizeof(T))));
}

}  // namespace masa::io
