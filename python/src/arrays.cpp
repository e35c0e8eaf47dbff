#include "arrays.hpp"

#include <sstream>

namespace masa::python {

std::string shapeText(const py::array& a) {
  std::ostringstream s;
  s << '(';
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s << (i ? ", " : "") << a.shape(i);
  s << (a.ndim() == 1 ? ",)" : ")");
  return s.str();
}

py::array_t<float, py::array::c_style> floatMatrix(const py::handle& in, int rows, int cols, const std::string& what,
                                                   const std::string& owner, bool accept_vector) {
  if (!py::isinstance<py::array>(in))
    throw py::type_error(owner + ": " + what + " must be a NumPy array, got " + std::string(py::str(in.get_type().attr("__name__"))));
  const auto a = py::reinterpret_borrow<py::array>(in);
  const char kind = a.dtype().kind();
  if (kind != 'f')
    throw py::type_error(owner + ": " + what + " have dtype " + std::string(py::str(a.dtype())) + ", expected float32 (or float64)");
  const std::string expected = "(" + (rows < 0 ? std::string("N") : std::to_string(rows)) + ", " + std::to_string(cols) + ")";
  const bool vector_ok = accept_vector && a.ndim() == 1 && a.shape(0) == cols;
  const bool matrix_ok = a.ndim() == 2 && (rows < 0 || a.shape(0) == rows) && a.shape(1) == cols;
  if (!vector_ok && !matrix_ok)
    throw py::value_error(owner + ": " + what + " have shape " + shapeText(a) + ", expected " + expected);
  auto m = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!m) throw py::error_already_set();
  if (vector_ok) m = m.reshape({py::ssize_t{1}, static_cast<py::ssize_t>(cols)});
  return m;
}

}  // namespace masa::python
