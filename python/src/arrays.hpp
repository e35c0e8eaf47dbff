// Checks of the arrays Python passes in, with messages in the tools' words (the task, what was
// given, what was expected), and fresh output arrays that C++ fills in place (no copy afterwards).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

namespace masa::python {

namespace py = pybind11;

// "(64, 12)" for messages.
std::string shapeText(const py::array& a);

// A float32, C-ordered view of `in` with shape (rows, cols): `in` itself when it already is one
// (no copy), else a converted copy of a float64 array. Any other dtype or shape throws: TypeError
// (py::type_error) for the dtype, ValueError for the shape, each naming `what` and `owner`.
// rows < 0: any number of rows; accept_vector: a 1-D array of cols values counts as one row.
py::array_t<float, py::array::c_style> floatMatrix(const py::handle& in, int rows, int cols, const std::string& what,
                                                   const std::string& owner, bool accept_vector = false);

template <class T>
py::array_t<T> newArray(std::vector<py::ssize_t> shape) {
  return py::array_t<T>(std::move(shape));
}

}  // namespace masa::python
