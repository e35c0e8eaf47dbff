// A task's symmetry as Python sees it (_masa.Symmetry): the group, the names of the observation
// and action dimensions, T_i as dense matrices, and T_i applied to batches of rows (the spec's
// sparse maps; a (B, dim) C-ordered array is the dim x B column-major batch masa uses, so the
// rows are transformed in place of a copy).
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "common/symmetry/symmetry_spec.hpp"

namespace masa::python {
namespace {

void checkElement(const sym::SymmetrySpec& s, int i) {
  if (i < 0 || i >= s.numAgents())
    throw py::index_error("symmetry " + s.name() + ": element " + std::to_string(i) + " of a group of " +
                          std::to_string(s.numAgents()));
}

py::array_t<double> dense(const sym::SparseMap& map) {
  const Eigen::MatrixXd d = map.toDense();
  auto out = newArray<double>({d.rows(), d.cols()});
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(out.mutable_data(), d.rows(),
                                                                                     d.cols()) = d;
  return out;
}

// Rows of x (B, dim) mapped by T_i: one row returns one row, a batch a batch.
py::array_t<float> applyRows(const sym::SymmetrySpec& s, const sym::SparseMap& map, const py::handle& x, int dim,
                             const char* what) {
  const auto in = floatMatrix(x, -1, dim, what, "symmetry " + s.name(), true);
  const py::ssize_t B = in.shape(0);
  auto out = newArray<float>({B, static_cast<py::ssize_t>(dim)});
  {
    py::gil_scoped_release released;
    Eigen::Map<const Mat<float>> src(in.data(), dim, B);
    Eigen::Map<Mat<float>> dst(out.mutable_data(), dim, B);
    map.apply<float>(src, dst);
  }
  if (py::reinterpret_borrow<py::array>(x).ndim() == 1) return out.reshape({static_cast<py::ssize_t>(dim)});
  return out;
}

}  // namespace

void bindSymmetry(py::module_& m) {
  py::class_<sym::SymmetrySpec>(m, "Symmetry")
      .def_static("load", &sym::SymmetrySpec::load, py::arg("path"))
      .def_static("parse", [](const std::string& text) { return sym::SymmetrySpec::parseString(text); },
                  py::arg("yaml_text"))
      .def_property_readonly("name", &sym::SymmetrySpec::name)
      .def_property_readonly("source", &sym::SymmetrySpec::source)
      .def_property_readonly("group_type", [](const sym::SymmetrySpec& s) {
        return s.group().type == sym::GroupType::kReflection ? "reflection" : "rotation";
      })
      .def_property_readonly("axis", [](const sym::SymmetrySpec& s) { return std::string(1, "xyz"[static_cast<int>(s.group().axis)]); })
      .def_property_readonly("order", &sym::SymmetrySpec::numAgents)
      .def_property_readonly("obs_dim", &sym::SymmetrySpec::obsDim)
      .def_property_readonly("act_dim", &sym::SymmetrySpec::actDim)
      .def_property_readonly("obs_names", &sym::SymmetrySpec::obsNames)
      .def_property_readonly("act_names", &sym::SymmetrySpec::actNames)
      .def("obs_matrix", [](const sym::SymmetrySpec& s, int i) { checkElement(s, i); return dense(s.obsTransform(i)); },
           py::arg("i"))
      .def("act_matrix", [](const sym::SymmetrySpec& s, int i) { checkElement(s, i); return dense(s.actTransform(i)); },
           py::arg("i"))
      .def(
          "transform_obs",
          [](const sym::SymmetrySpec& s, const py::handle& obs, int i) {
            checkElement(s, i);
            return applyRows(s, s.obsTransform(i), obs, s.obsDim(), "observations");
          },
          py::arg("obs"), py::arg("i"))
      .def(
          "transform_act",
          [](const sym::SymmetrySpec& s, const py::handle& act, int i) {
            checkElement(s, i);
            return applyRows(s, s.actTransform(i), act, s.actDim(), "actions");
          },
          py::arg("actions"), py::arg("i"));
}

}  // namespace masa::python
