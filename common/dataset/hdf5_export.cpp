#include "common/dataset/hdf5_export.hpp"

#include <hdf5.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string_view>
#include <sstream>
#include <stdexcept>

#include "common/integrity/sha256.hpp"

namespace masa::dataset {
namespace {

// The seal: HDF5 skips a file's user block (its first 512 bytes), so masa keeps there the SHA-256 of
// everything after it: "MASAH5S1" | u64 length of the rest | 32-byte SHA-256 of the rest. masa's
// reader checks it before HDF5 parses a byte (libhdf5 itself can crash on a damaged file: found by
// Hdf5ExportIntegrity's fuzzing). h5py and every other HDF5 reader read the file as usual.
constexpr hsize_t kUserBlockBytes = 512;
constexpr std::string_view kSealMagic = "MASAH5S1";
constexpr std::string_view kHdf5Signature = "\x89HDF\r\n\x1a\n";

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Writes the seal into the user block of a finished file, flushed to the disk.
void sealUserBlock(const std::string& path) {
  const std::string bytes = readAll(path);
  if (bytes.size() < kUserBlockBytes) throw std::runtime_error(path + ": no user block to seal");
  const std::string_view rest = std::string_view(bytes).substr(kUserBlockBytes);
  const integrity::Digest d = integrity::sha256(rest);
  const uint64_t n = rest.size();
  std::FILE* f = std::fopen(path.c_str(), "r+b");
  if (!f) throw std::runtime_error("cannot seal " + path);
  const bool ok = std::fwrite(kSealMagic.data(), 1, kSealMagic.size(), f) == kSealMagic.size() && std::fwrite(&n, sizeof n, 1, f) == 1 &&
                  std::fwrite(d.data(), 1, d.size(), f) == d.size() && std::fflush(f) == 0 && ::fsync(fileno(f)) == 0;
  if (std::fclose(f) != 0 || !ok) throw std::runtime_error("sealing " + path + " failed");
}

// Checks the seal of a file's bytes; a file that starts with HDF5's own signature is one exported
// before the seal (warned about). Throws naming the file and the reason.
void checkUserBlockSeal(const std::string& bytes, const std::string& path) {
  if (bytes.compare(0, kHdf5Signature.size(), kHdf5Signature) == 0) {
    std::fprintf(stderr, "masa: warning: %s: exported before masa sealed its files, so no checksum proves it intact\n", path.c_str());
    return;
  }
  if (bytes.size() < kUserBlockBytes || bytes.compare(0, kSealMagic.size(), kSealMagic) != 0)
    throw std::runtime_error(path + ": not a masa HDF5 export (no seal, and not HDF5's own start)");
  uint64_t n = 0;
  std::memcpy(&n, bytes.data() + kSealMagic.size(), sizeof n);
  integrity::Digest stored;
  std::memcpy(stored.data(), bytes.data() + kSealMagic.size() + sizeof n, stored.size());
  if (n != bytes.size() - kUserBlockBytes || integrity::sha256(std::string_view(bytes).substr(kUserBlockBytes)) != stored)
    throw std::runtime_error(path + ": checksum mismatch (file corrupted or truncated)");
}

// HDF5 handles closed on every path out.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t), const std::string& what) : id_(id), close_(close) {
    if (id_ < 0) throw std::runtime_error("HDF5: " + what + " failed");
  }
  ~Handle() { close_(id_); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  operator hid_t() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

void check(herr_t status, const std::string& what) {
  if (status < 0) throw std::runtime_error("HDF5: " + what + " failed");
}

// Chunked with HDF5's Fletcher-32 filter, so that any HDF5 reader (h5py too) refuses a damaged chunk.
void writeArray(hid_t parent, const char* name, hid_t type, const void* data, hsize_t rows, hsize_t cols) {
  const hsize_t dims[2] = {rows, cols};
  const int rank = cols > 0 ? 2 : 1;
  Handle space(H5Screate_simple(rank, dims, nullptr), H5Sclose, std::string("space of ") + name);
  Handle create(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "dataset properties");
  if (rows > 0) {
    const hsize_t row_bytes = std::max<hsize_t>(cols, 1) * H5Tget_size(type);
    const hsize_t chunk[2] = {std::clamp<hsize_t>((hsize_t{1} << 18) / row_bytes, 1, rows), cols};
    check(H5Pset_chunk(create, rank, chunk), std::string("chunks of ") + name);
    check(H5Pset_fletcher32(create), std::string("checksum of ") + name);
  }
  Handle set(H5Dcreate2(parent, name, type, space, H5P_DEFAULT, create, H5P_DEFAULT), H5Dclose,
             std::string("creating ") + name);
  if (rows > 0) check(H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), std::string("writing ") + name);
}

// Variable-length UTF-8: h5py reads it as a Python str.
void writeStringAttribute(hid_t obj, const char* name, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "string type");
  check(H5Tset_size(type, H5T_VARIABLE), "string size");
  check(H5Tset_cset(type, H5T_CSET_UTF8), "string character set");
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "scalar space");
  Handle attr(H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, std::string("attribute ") + name);
  const char* text = value.c_str();
  check(H5Awrite(attr, type, &text), std::string("writing attribute ") + name);
}

void writeIntAttribute(hid_t obj, const char* name, int64_t value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "scalar space");
  Handle attr(H5Acreate2(obj, name, H5T_NATIVE_INT64, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              std::string("attribute ") + name);
  check(H5Awrite(attr, H5T_NATIVE_INT64, &value), std::string("writing attribute ") + name);
}

std::string readStringAttribute(hid_t obj, const char* name) {
  Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose, std::string("attribute ") + name);
  Handle type(H5Aget_type(attr), H5Tclose, "attribute type");
  if (H5Tget_class(type) != H5T_STRING || !H5Tis_variable_str(type))
    throw std::runtime_error(std::string("HDF5: attribute ") + name + " is not a variable-length string");
  Handle mem(H5Tcopy(H5T_C_S1), H5Tclose, "string type");
  check(H5Tset_size(mem, H5T_VARIABLE), "string size");
  check(H5Tset_cset(mem, H5Tget_cset(type)), "string character set");
  char* text = nullptr;
  check(H5Aread(attr, mem, &text), std::string("reading attribute ") + name);
  std::string v = text ? text : "";
  H5free_memory(text);
  return v;
}

int64_t readIntAttribute(hid_t obj, const char* name) {
  Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose, std::string("attribute ") + name);
  int64_t v = 0;
  check(H5Aread(attr, H5T_NATIVE_INT64, &v), std::string("reading attribute ") + name);
  return v;
}

// Reads a whole array, checking its element count.
void readArray(hid_t parent, const char* name, hid_t type, void* out, hsize_t expected) {
  Handle set(H5Dopen2(parent, name, H5P_DEFAULT), H5Dclose, std::string("opening ") + name);
  Handle space(H5Dget_space(set), H5Sclose, std::string("space of ") + name);
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  if (n != static_cast<hssize_t>(expected))
    throw std::runtime_error(std::string("HDF5: ") + name + " has " + std::to_string(n) + " values, expected " +
                             std::to_string(expected));
  if (expected > 0) check(H5Dread(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out), std::string("reading ") + name);
}

hsize_t rowsOf(hid_t parent, const char* name) {
  Handle set(H5Dopen2(parent, name, H5P_DEFAULT), H5Dclose, std::string("opening ") + name);
  Handle space(H5Dget_space(set), H5Sclose, std::string("space of ") + name);
  hsize_t dims[2] = {0, 0};
  if (H5Sget_simple_extent_ndims(space) < 1) throw std::runtime_error(std::string("HDF5: ") + name + " is a scalar");
  H5Sget_simple_extent_dims(space, dims, nullptr);
  return dims[0];
}

}  // namespace

// Errors become exceptions with our message; HDF5's own error stack printout is turned off.
void quietHdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

void writeHdf5(const std::string& path, const TransitionDataset& d, const std::string& source) {
  quietHdf5();
  d.validate();
  const std::string tmp = path + ".tmp";
  {
    // HDF5's newer object headers and superblock carry checksums of their own (readable by 1.8 on).
    Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "file access properties");
    check(H5Pset_libver_bounds(access, H5F_LIBVER_V18, H5F_LIBVER_LATEST), "file format bounds");
    Handle create(H5Pcreate(H5P_FILE_CREATE), H5Pclose, "file creation properties");
    check(H5Pset_userblock(create, kUserBlockBytes), "user block");
    Handle file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, create, access), H5Fclose, "creating " + tmp);
    const hsize_t n = static_cast<hsize_t>(d.size());
    // Column-major obs_dim x N is row-major N x obs_dim: the bytes go as they are.
    writeArray(file, "observations", H5T_NATIVE_FLOAT, d.obs.data(), n, d.obs_dim);
    writeArray(file, "next_observations", H5T_NATIVE_FLOAT, d.next_obs.data(), n, d.obs_dim);
    writeArray(file, "actions", H5T_NATIVE_FLOAT, d.actions.data(), n, d.act_dim);
    writeArray(file, "rewards", H5T_NATIVE_FLOAT, d.rewards.data(), n, 0);
    writeArray(file, "terminals", H5T_NATIVE_UINT8, d.terminals.data(), n, 0);
    writeArray(file, "timeouts", H5T_NATIVE_UINT8, d.timeouts.data(), n, 0);
    const size_t m = d.episodes.size();
    std::vector<int64_t> index(static_cast<size_t>(n)), id(m), start(m), length(m), policy(m);
    std::vector<double> ret(m);
    std::vector<int8_t> success(m);
    for (size_t k = 0; k < m; ++k) {
      const EpisodeInfo& e = d.episodes[k];
      id[k] = e.episode_id;
      start[k] = e.start;
      length[k] = e.length;
      policy[k] = e.policy_id;
      ret[k] = e.ret;
      success[k] = e.success;
      for (int64_t t = e.start; t < e.start + e.length; ++t) index[static_cast<size_t>(t)] = static_cast<int64_t>(k);
    }
    writeArray(file, "episode_index", H5T_NATIVE_INT64, index.data(), n, 0);
    Handle eps(H5Gcreate2(file, "episodes", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "group episodes");
    writeArray(eps, "id", H5T_NATIVE_INT64, id.data(), m, 0);
    writeArray(eps, "start", H5T_NATIVE_INT64, start.data(), m, 0);
    writeArray(eps, "length", H5T_NATIVE_INT64, length.data(), m, 0);
    writeArray(eps, "return", H5T_NATIVE_DOUBLE, ret.data(), m, 0);
    writeArray(eps, "success", H5T_NATIVE_INT8, success.data(), m, 0);
    writeArray(eps, "policy", H5T_NATIVE_INT64, policy.data(), m, 0);
    std::string names;
    for (size_t i = 0; i < d.policy_names.size(); ++i) names += (i ? "\n" : "") + d.policy_names[i];
    writeStringAttribute(file, "task", d.task);
    writeIntAttribute(file, "obs_dim", d.obs_dim);
    writeIntAttribute(file, "act_dim", d.act_dim);
    writeStringAttribute(file, "policy_names", names);
    writeStringAttribute(file, "source", source);
    check(H5Fflush(file, H5F_SCOPE_GLOBAL), "flush");
  }
  sealUserBlock(tmp);
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error("cannot move " + tmp + " to " + path + ": " + ec.message());
}

TransitionDataset readHdf5(const std::string& path) {
  quietHdf5();
  if (!std::filesystem::exists(path)) throw std::runtime_error("no such HDF5 file: " + path);
  checkUserBlockSeal(readAll(path), path);  // before HDF5 parses a byte of it
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, "opening " + path);
  TransitionDataset d;
  d.task = readStringAttribute(file, "task");
  d.obs_dim = static_cast<int>(readIntAttribute(file, "obs_dim"));
  d.act_dim = static_cast<int>(readIntAttribute(file, "act_dim"));
  if (d.obs_dim <= 0 || d.act_dim <= 0) throw std::runtime_error(path + ": bad obs_dim / act_dim");
  const hsize_t n = rowsOf(file, "rewards");
  d.obs.resize(d.obs_dim, static_cast<Eigen::Index>(n));
  d.next_obs.resize(d.obs_dim, static_cast<Eigen::Index>(n));
  d.actions.resize(d.act_dim, static_cast<Eigen::Index>(n));
  d.rewards.resize(static_cast<Eigen::Index>(n));
  d.terminals.resize(n);
  d.timeouts.resize(n);
  readArray(file, "observations", H5T_NATIVE_FLOAT, d.obs.data(), n * d.obs_dim);
  readArray(file, "next_observations", H5T_NATIVE_FLOAT, d.next_obs.data(), n * d.obs_dim);
  readArray(file, "actions", H5T_NATIVE_FLOAT, d.actions.data(), n * d.act_dim);
  readArray(file, "rewards", H5T_NATIVE_FLOAT, d.rewards.data(), n);
  readArray(file, "terminals", H5T_NATIVE_UINT8, d.terminals.data(), n);
  readArray(file, "timeouts", H5T_NATIVE_UINT8, d.timeouts.data(), n);
  Handle eps(H5Gopen2(file, "episodes", H5P_DEFAULT), H5Gclose, "group episodes");
  const hsize_t m = rowsOf(eps, "id");
  std::vector<int64_t> id(m), start(m), length(m), policy(m);
  std::vector<double> ret(m);
  std::vector<int8_t> success(m);
  readArray(eps, "id", H5T_NATIVE_INT64, id.data(), m);
  readArray(eps, "start", H5T_NATIVE_INT64, start.data(), m);
  readArray(eps, "length", H5T_NATIVE_INT64, length.data(), m);
  readArray(eps, "return", H5T_NATIVE_DOUBLE, ret.data(), m);
  readArray(eps, "success", H5T_NATIVE_INT8, success.data(), m);
  readArray(eps, "policy", H5T_NATIVE_INT64, policy.data(), m);
  for (hsize_t k = 0; k < m; ++k)
    d.episodes.push_back({id[k], static_cast<int32_t>(policy[k]), start[k], static_cast<int32_t>(length[k]), ret[k], success[k]});
  const std::string names_text = readStringAttribute(file, "policy_names");
  std::istringstream names(names_text);
  for (std::string line; std::getline(names, line);) d.policy_names.push_back(line);
  d.validate();
  return d;
}

}  // namespace masa::dataset
