// Parameter files, little-endian as written by the host:
//   "MASAPAR1" | u32 sizeof(scalar) | u32 segment count |
//   per segment: u32 name length, name bytes, i32 rows, i32 cols | all values in segment order.
#include "common/nn/serialize.hpp"

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <istream>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "common/core/binary_io.hpp"
#include "common/core/check.hpp"

namespace masa::nn {

namespace {
constexpr char kMagic[8] = {'M', 'A', 'S', 'A', 'P', 'A', 'R', '1'};
constexpr std::uint32_t kMaxNameLength = 4096;  // longer means a corrupt or foreign file

using io::writePod;

class Reader {
 public:
  Reader(std::istream& is, const std::string& source) : is_(is), source_(source) {}
  template <typename T>
  void array(T* dst, std::size_t n, const std::string& what) {
    if (!io::readArray(is_, dst, n)) fail("file ends while reading " + what);
  }
  template <typename T>
  T pod(const std::string& what) {
    T v;
    if (!io::readPod(is_, v)) fail("file ends while reading " + what);
    return v;
  }
  [[noreturn]] void fail(const std::string& msg) const { throw std::runtime_error(source_ + ": " + msg); }

 private:
  std::istream& is_;
  const std::string& source_;
};

std::string shapeOf(const std::string& name, std::int32_t rows, std::int32_t cols) {
  std::ostringstream os;
  os << "'" << name << "' " << rows << "x" << cols;
  return os.str();
}
}  // namespace

template <typename S>
void saveParameters(const ParameterSet<S>& params, std::ostream& os) {
  MASA_CHECK(params.finalized(), "saveParameters needs a finalized parameter set");
  os.write(kMagic, sizeof(kMagic));
  writePod(os, static_cast<std::uint32_t>(sizeof(S)));
  writePod(os, static_cast<std::uint32_t>(params.segments().size()));
  for (const ParameterSegment& s : params.segments()) {
    writePod(os, static_cast<std::uint32_t>(s.name.size()));
    io::writeArray(os, s.name.data(), s.name.size());
    writePod(os, static_cast<std::int32_t>(s.rows));
    writePod(os, static_cast<std::int32_t>(s.cols));
  }
  io::writeArray(os, params.values().data(), static_cast<std::size_t>(params.size()));
  if (!os) throw std::runtime_error("saveParameters: write failed");
}

template <typename S>
void loadParameters(ParameterSet<S>& params, std::istream& is, const std::string& source_name) {
  MASA_CHECK(params.finalized(), "loadParameters needs a finalized parameter set");
  Reader in(is, source_name);
  char magic[sizeof(kMagic)];
  in.array(magic, sizeof(magic), "the magic");
  if (std::memcmp(magic, kMagic, sizeof(magic)) != 0) in.fail("not a masa parameter file (bad magic)");
  const auto scalar = in.pod<std::uint32_t>("the scalar type");
  if (scalar != sizeof(S))
    in.fail("scalar size is " + std::to_string(scalar) + " bytes in the file but " + std::to_string(sizeof(S)) +
            " in the model");
  const auto count = in.pod<std::uint32_t>("the segment count");

  const auto& segs = params.segments();
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::string idx = std::to_string(i + 1);
    const auto len = in.pod<std::uint32_t>("the name of segment " + idx);
    if (len > kMaxNameLength) in.fail("segment " + idx + " has a name of " + std::to_string(len) + " bytes (corrupt file)");
    std::string name(len, '\0');
    in.array(name.data(), len, "the name of segment " + idx);
    const auto rows = in.pod<std::int32_t>("the shape of segment " + idx);
    const auto cols = in.pod<std::int32_t>("the shape of segment " + idx);
    if (i >= segs.size())
      in.fail("segment " + idx + " is " + shapeOf(name, rows, cols) + " in the file but the model has only " +
              std::to_string(segs.size()) + " segments");
    const ParameterSegment& s = segs[i];
    if (name != s.name || rows != s.rows || cols != s.cols)
      in.fail("segment " + idx + " is " + shapeOf(name, rows, cols) + " in the file but " +
              shapeOf(s.name, s.rows, s.cols) + " in the model");
  }
  if (count < segs.size()) {
    const ParameterSegment& s = segs[count];
    in.fail("the file has " + std::to_string(count) + " segments but the model has " + std::to_string(segs.size()) +
            ", starting with segment " + std::to_string(count + 1) + " " + shapeOf(s.name, s.rows, s.cols));
  }
  // Read into a temporary so that a truncated file leaves the model untouched.
  Vec<S> values(params.size());
  in.array(values.data(), static_cast<std::size_t>(params.size()), "the values");
  params.values() = values;
}

template <typename S>
void saveParameters(const ParameterSet<S>& params, const std::string& path) {
  // Written beside the target and renamed, so a reader never sees a half-written file.
  const std::string tmp = path + ".tmp";
  {
    std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
    if (!os) throw std::runtime_error(tmp + ": cannot open for writing");
    saveParameters(params, os);
    os.close();
    if (!os) throw std::runtime_error(tmp + ": write failed");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw std::runtime_error(path + ": cannot rename " + tmp + " to it: " + std::strerror(errno));
}

template <typename S>
void loadParameters(ParameterSet<S>& params, const std::string& path) {
  std::ifstream is(path, std::ios::binary);
  if (!is) throw std::runtime_error(path + ": cannot open for reading");
  loadParameters(params, is, path);
}

template void saveParameters<float>(const ParameterSet<float>&, std::ostream&);
template void saveParameters<double>(const ParameterSet<double>&, std::ostream&);
template void loadParameters<float>(ParameterSet<float>&, std::istream&, const std::string&);
template void loadParameters<double>(ParameterSet<double>&, std::istream&, const std::string&);
template void saveParameters<float>(const ParameterSet<float>&, const std::string&);
template void saveParameters<double>(const ParameterSet<double>&, const std::string&);
template void loadParameters<float>(ParameterSet<float>&, const std::string&);
template void loadParameters<double>(ParameterSet<double>&, const std::string&);

}  // namespace masa::nn
