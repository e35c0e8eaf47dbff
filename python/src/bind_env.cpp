// The batched environment and the run configuration as Python sees them: _masa.RunConfig,
// _masa.load_config and _masa.BatchedEnv (python/masa/env.py wraps it in Gymnasium's vector API).
#include <pybind11/stl.h>

#include <optional>

#include "arrays.hpp"
#include "batched_env.hpp"
#include "bindings.hpp"

namespace masa::python {

void bindEnv(py::module_& m) {
  py::class_<config::RunConfig>(m, "RunConfig")
      .def_readonly("task", &config::RunConfig::task)
      .def_property_readonly("method", [](const config::RunConfig& c) { return model::methodName(c.method); })
      .def_readonly("seed", &config::RunConfig::seed)
      .def_readonly("spec_path", &config::RunConfig::spec_path)
      .def_property_readonly("yaml", [](const config::RunConfig& c) { return config::dumpResolved(c); })
      .def("symmetry", [](const config::RunConfig& c) { return sym::SymmetrySpec::load(c.spec_path); });

  // The run configuration the tools build: defaults, the task file, overrides ("key=value" or
  // "@recipe"), or a run directory's config.yaml as the base. Errors are the tools' (ConfigError).
  m.def(
      "load_config",
      [](const std::vector<std::string>& overrides, const std::string& base_file) {
        return config::loadRunConfig(config::defaultConfigsDir(), overrides, base_file);
      },
      py::arg("overrides"), py::arg("base_file") = "");
  m.def("configs_dir", [] { return config::defaultConfigsDir(); });
  // The source tree the module was built from: the tasks' models, deploy/train.sh.
  m.def("source_dir", [] { return std::string(MASA_SOURCE_DIR); });

  py::class_<BatchedEnv>(m, "BatchedEnv")
      .def(py::init([](const config::RunConfig& c, int num_envs, int threads) {
             const auto spec = sym::SymmetrySpec::load(c.spec_path);
             return std::make_unique<BatchedEnv>(c, spec, num_envs, threads);
           }),
           py::arg("config"), py::arg("num_envs"), py::arg("threads"))
      .def(py::init([](const config::RunConfig& c, const sym::SymmetrySpec& spec, int num_envs, int threads) {
             return std::make_unique<BatchedEnv>(c, spec, num_envs, threads);
           }),
           py::arg("config"), py::arg("spec"), py::arg("num_envs"), py::arg("threads"))
      .def_property_readonly("num_envs", &BatchedEnv::numEnvs)
      .def_property_readonly("obs_dim", &BatchedEnv::obsDim)
      .def_property_readonly("act_dim", &BatchedEnv::actDim)
      .def_property_readonly("max_episode_steps", &BatchedEnv::maxEpisodeSteps)
      .def_property_readonly("control_timestep", &BatchedEnv::controlTimestep)
      .def_property_readonly("task", &BatchedEnv::taskName)
      .def_property_readonly("reward_terms", &BatchedEnv::rewardTermNames)
      .def_property_readonly("symmetry", &BatchedEnv::spec)
      // seed None: each environment goes on from its generator as it stands.
      .def(
          "reset",
          [](BatchedEnv& env, std::optional<uint64_t> seed) {
            auto obs = newArray<float>({env.numEnvs(), env.obsDim()});
            float* o = obs.mutable_data();
            {
              py::gil_scoped_release released;
              if (seed) env.reset(*seed, o);
              else env.resetContinuing(o);
            }
            return obs;
          },
          py::arg("seed") = py::none())
      // Returns obs, reward, terminated, truncated, ended, final_obs, episode_return,
      // episode_length, episode_success: new arrays, written once by the tasks' own code.
      .def("step", [](BatchedEnv& env, const py::handle& actions) {
        const int E = env.numEnvs(), d = env.obsDim();
        const auto act = floatMatrix(actions, E, env.actDim(), "actions", "task " + env.taskName());
        auto obs = newArray<float>({E, d});
        auto reward = newArray<double>({E});
        auto terminated = newArray<bool>({E});
        auto truncated = newArray<bool>({E});
        auto ended = newArray<bool>({E});
        auto final_obs = newArray<float>({E, d});
        auto ep_return = newArray<double>({E});
        auto ep_length = newArray<int32_t>({E});
        auto ep_success = newArray<int8_t>({E});
        const StepBuffers out{obs.mutable_data(),       reward.mutable_data(),    terminated.mutable_data(),
                              truncated.mutable_data(), ended.mutable_data(),     final_obs.mutable_data(),
                              ep_return.mutable_data(), ep_length.mutable_data(), ep_success.mutable_data()};
        const float* a = act.data();
        {
          py::gil_scoped_release released;
          env.step(a, out);
        }
        return py::make_tuple(obs, reward, terminated, truncated, ended, final_obs, ep_return, ep_length, ep_success);
      });
}

}  // namespace masa::python
