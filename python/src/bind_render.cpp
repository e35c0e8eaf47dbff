// Frames of an environment as RGB arrays (_masa.Renderer), by the renderer masa_eval films with:
// a camera following the robot's root body. Needs an OpenGL context (a display, or xvfb-run);
// without one the constructor raises the renderer's message.
#include "arrays.hpp"
#include "batched_env.hpp"
#include "bindings.hpp"
#include "common/render/offscreen_renderer.hpp"

namespace masa::python {
namespace {

struct Renderer {
  std::unique_ptr<render::OffscreenRenderer> renderer;
};

}  // namespace

void bindRender(py::module_& m) {
  py::class_<Renderer>(m, "Renderer")
      .def(py::init([](const BatchedEnv& env, int width, int height) {
             if (width < 16 || height < 16 || width > 8192 || height > 8192)
               throw py::value_error("render: width and height must be in [16, 8192], got " + std::to_string(width) +
                                     " x " + std::to_string(height));
             auto r = std::make_unique<Renderer>();
             const task::Task& first = env.env(0);
             r->renderer = std::make_unique<render::OffscreenRenderer>(first.model(), width, height);
             r->renderer->trackBody(render::rootBody(first.model()),
                                    render::robotViewDistance(first.model(), first.data()), 135.0, -20.0);
             return r;
           }),
           py::arg("env"), py::arg("width"), py::arg("height"),
           py::keep_alive<1, 2>())  // the environment (its model) lives as long as its renderer
      .def_property_readonly("size", [](const Renderer& r) {
        return py::make_tuple(r.renderer->width(), r.renderer->height());
      })
      .def(
          "frame",
          [](Renderer& r, const BatchedEnv& env, int e) {
            if (e < 0 || e >= env.numEnvs())
              throw py::index_error("render: environment " + std::to_string(e) + " of " + std::to_string(env.numEnvs()));
            const auto& rgb = r.renderer->render(env.env(e).data());
            auto out = newArray<uint8_t>({r.renderer->height(), r.renderer->width(), 3});
            std::copy(rgb.begin(), rgb.end(), out.mutable_data());
            return out;
          },
          py::arg("env"), py::arg("index"));
}

}  // namespace masa::python
