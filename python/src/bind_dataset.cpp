// Offline datasets as arrays (_masa.read_dataset): masa_dataset's LCM logs (one or several, read
// and checked by the tools' reader) or its HDF5 export, as rows (N, dim) for NumPy users.
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "common/dataset/dataset_log.hpp"
#include "common/dataset/hdf5_export.hpp"

namespace masa::python {
namespace {

bool isHdf5(const std::string& path) {
  const auto dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  return ext == ".h5" || ext == ".hdf5";
}

// features x N column-major is N x features row-major: the same bytes.
py::array_t<float> rows(const Mat<float>& m) {
  auto out = newArray<float>({m.cols(), m.rows()});
  std::copy(m.data(), m.data() + m.size(), out.mutable_data());
  return out;
}

}  // namespace

void bindDataset(py::module_& m) {
  m.def(
      "read_dataset",
      [](const std::vector<std::string>& paths) {
        if (paths.empty()) throw py::value_error("read_dataset: no files");
        dataset::TransitionDataset d;
        dataset::LogReadReport report;
        {
          py::gil_scoped_release released;
          if (paths.size() == 1 && isHdf5(paths[0])) d = dataset::readHdf5(paths[0]);
          else d = dataset::readDatasetLogs(paths, &report);
          d.validate();
        }
        const py::ssize_t n = d.size(), k = static_cast<py::ssize_t>(d.episodes.size());
        auto rewards = newArray<float>({n});
        std::copy(d.rewards.data(), d.rewards.data() + n, rewards.mutable_data());
        auto terminals = newArray<bool>({n}), timeouts = newArray<bool>({n});
        for (py::ssize_t i = 0; i < n; ++i) {
          terminals.mutable_at(i) = d.terminals[i] != 0;
          timeouts.mutable_at(i) = d.timeouts[i] != 0;
        }
        auto start = newArray<int64_t>({k});
        auto length = newArray<int32_t>({k}), policy = newArray<int32_t>({k});
        auto ret = newArray<double>({k});
        auto success = newArray<int8_t>({k});
        for (py::ssize_t j = 0; j < k; ++j) {
          const auto& e = d.episodes[j];
          start.mutable_at(j) = e.start;
          length.mutable_at(j) = e.length;
          policy.mutable_at(j) = e.policy_id;
          ret.mutable_at(j) = e.ret;
          success.mutable_at(j) = e.success;
        }
        py::dict episodes;
        episodes["start"] = start;
        episodes["length"] = length;
        episodes["return"] = ret;
        episodes["success"] = success;
        episodes["policy"] = policy;
        py::dict r;
        r["task"] = d.task;
        r["observations"] = rows(d.obs);
        r["actions"] = rows(d.actions);
        r["rewards"] = rewards;
        r["next_observations"] = rows(d.next_obs);
        r["terminals"] = terminals;
        r["timeouts"] = timeouts;
        r["episodes"] = episodes;
        r["policy_names"] = d.policy_names;
        r["report"] = report.files ? report.summary() : std::string();
        return r;
      },
      py::arg("paths"));
}

}  // namespace masa::python
