#include "batched_env.hpp"

#include <algorithm>
#include <exception>
#include <mutex>
#include <stdexcept>

#include "tasks/tasks.hpp"

namespace masa::python {
namespace {

// Runs body(e) for every environment on up to `threads` threads. An exception must not leave an
// OpenMP region (the process would end): the first one is kept and rethrown after the loop, so
// Python sees it as an exception.
template <class Body>
void forEachEnv(int num_envs, int threads, Body&& body) {
  std::exception_ptr first;
  std::mutex first_mutex;
#pragma omp parallel for num_threads(std::max(1, std::min(threads, num_envs))) schedule(static)
  for (int e = 0; e < num_envs; ++e) {
    try {
      body(e);
    } catch (...) {
      std::lock_guard<std::mutex> lock(first_mutex);
      if (!first) first = std::current_exception();
    }
  }
  if (first) std::rethrow_exception(first);
}

}  // namespace

BatchedEnv::BatchedEnv(const config::RunConfig& config, const sym::SymmetrySpec& spec, int num_envs, int threads)
    : spec_(spec), threads_(threads) {
  if (num_envs <= 0) throw std::invalid_argument("num_envs must be positive, got " + std::to_string(num_envs));
  if (threads <= 0) throw std::invalid_argument("num_threads must be positive, got " + std::to_string(threads));
  factory_ = std::make_unique<task::TaskFactory>(task::taskCatalog(), config.task, spec_, config.env, config.origin);
  envs_.reserve(num_envs);
  for (int e = 0; e < num_envs; ++e) envs_.push_back(factory_->create());
  rngs_.resize(num_envs);
}

void BatchedEnv::reset(uint64_t seed, float* obs) {
  std::lock_guard<std::mutex> lock(busy_);
  for (int e = 0; e < numEnvs(); ++e) rngs_[e].seed(seed + static_cast<uint64_t>(e));
  resetEnvironments(obs);
}

void BatchedEnv::resetContinuing(float* obs) {
  std::lock_guard<std::mutex> lock(busy_);
  resetEnvironments(obs);
}

void BatchedEnv::resetEnvironments(float* obs) {
  const int d = obsDim();
  forEachEnv(numEnvs(), threads_, [&](int e) {
    envs_[e]->reset(rngs_[e]);
    envs_[e]->observe(obs + static_cast<size_t>(e) * d);
  });
}

void BatchedEnv::step(const float* actions, const StepBuffers& out) {
  std::lock_guard<std::mutex> lock(busy_);
  const int d = obsDim(), a = actDim();
  forEachEnv(numEnvs(), threads_, [&](int e) {
    task::Task& env = *envs_[e];
    const task::StepOutcome r = env.step(actions + static_cast<size_t>(e) * a);
    const bool ended = r.terminated || r.truncated;
    out.reward[e] = r.reward;
    out.terminated[e] = r.terminated;
    out.truncated[e] = r.truncated;
    out.episode_ended[e] = ended;
    float* final_obs = out.final_obs + static_cast<size_t>(e) * d;
    if (ended) {
      env.observe(final_obs);
      const task::EpisodeStats& st = env.episode();
      out.episode_return[e] = st.ret;
      out.episode_length[e] = st.length;
      out.episode_success[e] = st.has_success ? (st.success ? 1 : 0) : -1;
      env.reset(rngs_[e]);
    } else {
      std::fill(final_obs, final_obs + d, 0.0f);
      out.episode_return[e] = 0.0;
      out.episode_length[e] = 0;
      out.episode_success[e] = -1;
    }
    env.observe(out.obs + static_cast<size_t>(e) * d);
  });
}

}  // namespace masa::python
