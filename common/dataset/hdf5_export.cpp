#include "common/dataset/hdf5_export.hpp"

#include <hdf5.h>

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace masa::dataset {
namespace {

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

void writeArray(hid_t parent, const char* name, hid_t type, const void* data, hsize_t rows, hsize_t cols) {
  const hsize_t dims[2] = {rows, cols};
  Handle space(H5Screate_simple(cols > 0 ? 2 : 1, dims, nullptr), H5Sclose, std::string("space of ") + name);
  Handle set(H5Dcreate2(parent, name, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose,
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
    Handle file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose, "creating " + tmp);
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
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error("cannot move " + tmp + " to " + path + ": " + ec.message());
}

TransitionDataset readHdf5(const std::string& path) {
  quietHdf5();
  if (!std::filesystem::exists(path)) throw std::runtime_error("no such HDF5 file: " + path);
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
  std::istringstream names(readStringAttribute(file, "policy_names"));
  for (std::string line; std::getline(names, line);) d.policy_names.push_back(line);
  d.validate();
  return d;
}

}  // namespace masa::dataset
