// The parts of the _masa extension module, one file each; module.cpp calls them in order.
#pragma once

#include <pybind11/pybind11.h>

namespace masa::python {

namespace py = pybind11;

void bindSymmetry(py::module_& m);  // bind_symmetry.cpp: groups, transforms
void bindEnv(py::module_& m);       // bind_env.cpp: run configs, the batched environment
void bindPolicy(py::module_& m);    // bind_policy.cpp: policy files, acting, evaluation
void bindRender(py::module_& m);    // bind_render.cpp: frames as RGB arrays
void bindDataset(py::module_& m);   // bind_dataset.cpp: offline datasets as arrays

}  // namespace masa::python
