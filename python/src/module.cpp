// _masa: the C++ half of `import masa` (python/masa/ is the Python half). Errors keep the tools'
// messages: ConfigError becomes masa.ConfigError (a ValueError), std::invalid_argument a
// ValueError, other std::exceptions a RuntimeError (pybind11's own translation).
#include "bindings.hpp"

#include "common/core/config_error.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_masa, m) {
  m.doc() = "masa's tasks, symmetries and policies (the C++ libraries)";
  static py::exception<masa::ConfigError> config_error(m, "ConfigError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const masa::ConfigError& e) {
      config_error(e.what());
    }
  });
  masa::python::bindSymmetry(m);
  masa::python::bindEnv(m);
  masa::python::bindPolicy(m);
  masa::python::bindRender(m);
  masa::python::bindDataset(m);
}
