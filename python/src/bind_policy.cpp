// Policies as Python sees them (_masa.Policy): a policy file loaded, sealed and checked as
// masa_eval loads it (the seal, then the equivariance of a MASA policy), acting on a batch with
// its normalizer; a fresh model of any method (for tests and comparisons); and the evaluation
// masa_eval runs, as arrays.
#include <pybind11/stl.h>

#include <mutex>

#include "arrays.hpp"
#include "bindings.hpp"
#include "common/policy/policy_file.hpp"
#include "common/sim/policy_evaluator.hpp"
#include "tasks/tasks.hpp"

namespace masa::python {
namespace {

// A loaded policy; the model's forward pass keeps scratch, so one call acts at a time.
struct PolicyHandle {
  policy::LoadedPolicy loaded;
  double symmetry_error = 0.0;
  std::mutex acting;
};

// Actions for rows of observations, one column at a time as masa_eval computes them: Eigen
// multiplies one column and a batch with different summation orders, and a policy's action must
// not depend on what else is in the batch.
py::array_t<float> act(PolicyHandle& p, const py::handle& obs_in) {
  auto& model = *p.loaded.model;
  const std::string owner = "policy " + p.loaded.source;
  const auto obs = floatMatrix(obs_in, -1, model.obsDim(), "observations", owner, true);
  const py::ssize_t B = obs.shape(0);
  const int d = model.obsDim(), a = model.actDim();
  auto out = newArray<float>({B, static_cast<py::ssize_t>(a)});
  float* dst = out.mutable_data();
  const float* src = obs.data();
  {
    py::gil_scoped_release released;
    std::lock_guard<std::mutex> lock(p.acting);
    for (py::ssize_t b = 0; b < B; ++b) {
      Eigen::Map<const Mat<float>> o(src + b * d, d, 1);
      Eigen::Map<Mat<float>>(dst + b * a, a, 1) = model.actMean(o);
    }
  }
  if (py::reinterpret_borrow<py::array>(obs_in).ndim() == 1) return out.reshape({static_cast<py::ssize_t>(a)});
  return out;
}

py::dict evaluate(PolicyHandle& p, int episodes, uint64_t seed, bool deterministic, int max_steps, int threads) {
  task::EvalOptions o;
  o.episodes = episodes;
  o.seed = seed;
  o.deterministic = deterministic;
  o.max_steps = max_steps;
  o.threads = threads;
  task::EvalSummary s;
  {
    py::gil_scoped_release released;
    std::lock_guard<std::mutex> lock(p.acting);
    const auto& c = p.loaded.config;
    task::TaskFactory factory(task::taskCatalog(), c.task, p.loaded.spec, c.env, c.origin);
    s = task::PolicyEvaluator(factory, *p.loaded.model).run(o);
  }
  const py::ssize_t n = static_cast<py::ssize_t>(s.episodes.size());
  const py::ssize_t T = static_cast<py::ssize_t>(s.term_names.size()), P = static_cast<py::ssize_t>(s.progress_names.size());
  auto seeds = newArray<uint64_t>({n});
  auto ret = newArray<double>({n});
  auto length = newArray<int32_t>({n});
  auto terminated = newArray<bool>({n});
  auto success = newArray<int8_t>({n});
  auto terms = newArray<double>({n, T});
  auto progress = newArray<double>({n, P});
  for (py::ssize_t k = 0; k < n; ++k) {
    const auto& e = s.episodes[k];
    seeds.mutable_at(k) = e.seed;
    ret.mutable_at(k) = e.ret;
    length.mutable_at(k) = e.length;
    terminated.mutable_at(k) = e.terminated;
    success.mutable_at(k) = static_cast<int8_t>(e.success);
    for (py::ssize_t j = 0; j < T; ++j) terms.mutable_at(k, j) = e.terms[j];
    for (py::ssize_t j = 0; j < P; ++j) progress.mutable_at(k, j) = e.progress[j];
  }
  py::dict r;
  r["seed"] = seeds;
  r["return"] = ret;
  r["length"] = length;
  r["terminated"] = terminated;
  r["success"] = success;
  r["term_names"] = s.term_names;
  r["terms"] = terms;
  r["progress_names"] = s.progress_names;
  r["progress"] = progress;
  r["success_rate"] = s.success_rate;
  r["summary"] = task::formatSummary(s);
  return r;
}

}  // namespace

void bindPolicy(py::module_& m) {
  py::class_<PolicyHandle>(m, "Policy")
      .def_static(
          "load",
          [](const std::string& path) {
            auto p = std::make_unique<PolicyHandle>();
            py::gil_scoped_release released;
            p->loaded = policy::loadPolicyFile(path);
            p->symmetry_error = policy::checkPolicySymmetry(p->loaded);
            return p;
          },
          py::arg("path"))
      // A freshly initialized model of a config's method, drawn from Rng(seed): an untrained
      // policy of any method (an SA one is not equivariant, which the check must see).
      .def_static(
          "initial",
          [](const config::RunConfig& c, uint64_t seed) {
            auto p = std::make_unique<PolicyHandle>();
            p->loaded.config = c;
            p->loaded.spec = sym::SymmetrySpec::load(c.spec_path);
            p->loaded.model = std::make_unique<model::ActorCritic<float>>(p->loaded.spec, c.model);
            Rng rng(seed);
            p->loaded.model->initialize(rng);
            p->loaded.source = "initial " + c.task + " " + model::methodName(c.method) + " policy (seed " + std::to_string(seed) + ")";
            return p;
          },
          py::arg("config"), py::arg("seed") = 0)
      .def_property_readonly("source", [](const PolicyHandle& p) { return p.loaded.source; })
      .def_property_readonly("integrity", [](const PolicyHandle& p) { return p.loaded.integrity; })
      .def_property_readonly("task", [](const PolicyHandle& p) { return p.loaded.config.task; })
      .def_property_readonly("method", [](const PolicyHandle& p) { return model::methodName(p.loaded.config.method); })
      .def_property_readonly("config", [](const PolicyHandle& p) { return p.loaded.config; })
      .def_property_readonly("symmetry", [](const PolicyHandle& p) { return p.loaded.spec; })
      .def_property_readonly("symmetry_error", [](const PolicyHandle& p) { return p.symmetry_error; })
      .def_property_readonly("obs_dim", [](const PolicyHandle& p) { return p.loaded.model->obsDim(); })
      .def_property_readonly("act_dim", [](const PolicyHandle& p) { return p.loaded.model->actDim(); })
      .def_property_readonly("squashed", [](const PolicyHandle& p) {
        return p.loaded.model->config().squash == model::ActionSquash::kTanh;
      })
      .def("act", &act, py::arg("obs"))
      .def("evaluate", &evaluate, py::arg("episodes") = 20, py::arg("seed") = 0, py::arg("deterministic") = true,
           py::arg("max_steps") = 0, py::arg("threads") = 1);
}

}  // namespace masa::python
