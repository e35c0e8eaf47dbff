// The rollout's fields, listed once, and the copy of environments between rollouts that is made
// from the list.
//
// Four stages hold rollout data in the same step-major layout (rollout.hpp): the actor's Rollout,
// the wire chunk (lcmt_rollout_chunk: a run of whole environments), the learner's intake pool and
// its batch (both Rollouts). Their arrays have the same names, so one list of them serves all:
// what a stage sizes, clears, checks and copies is walked from forEachStepArrayOf and the
// event lists below, and environments move between any two stages with copyEnvironments, with
// their truncations and episodes renumbered on the way. A field added to the list is handled
// everywhere; one missing from a stage does not compile.
//
// Src and Dst are rollout::Rollout or masa::lcmt_rollout_chunk (any type with these members).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

namespace masa::rollout {

// The per-step arrays, of two rollouts side by side: f(a's array, b's array, values per (step,
// environment), rows beyond the horizon). obs has one row more (the bootstrap observation). The
// one list of them: everything below walks it.
template <class A, class B, class F>
void forEachStepArrayOf(A& a, B& b, int obs_dim, int act_dim, F&& f) {
  f(a.obs, b.obs, obs_dim, 1);
  f(a.actions, b.actions, act_dim, 0);
  f(a.mean, b.mean, act_dim, 0);
  f(a.log_prob, b.log_prob, 1, 0);
  f(a.reward, b.reward, 1, 0);
  f(a.terminated, b.terminated, 1, 0);
  f(a.truncated, b.truncated, 1, 0);
}
template <class R, class F>
void forEachStepArray(R& r, int obs_dim, int act_dim, F&& f) {
  forEachStepArrayOf(r, r, obs_dim, act_dim, [&](auto& x, auto&, int width, int extra_rows) { f(x, width, extra_rows); });
}

// The event arrays: f(array, values per event). Truncations (final_index, final_obs) and
// finished episodes (the episode_* arrays; term sums are num_terms per episode).
template <class R, class F>
void forEachFinalArray(R& r, int obs_dim, F&& f) {
  f(r.final_index, 1);
  f(r.final_obs, obs_dim);
}
template <class R, class F>
void forEachEpisodeArray(R& r, int num_terms, F&& f) {
  f(r.episode_env, 1);
  f(r.episode_return, 1);
  f(r.episode_length, 1);
  f(r.episode_success, 1);
  f(r.episode_term_sums, num_terms);
}

// Sizes the per-step arrays for `envs` environments of `horizon` steps.
template <class R>
void resizeSteps(R& r, int horizon, int envs, int obs_dim, int act_dim) {
  forEachStepArray(r, obs_dim, act_dim, [&](auto& a, int width, int extra_rows) {
    a.resize(static_cast<std::size_t>(horizon + extra_rows) * envs * width);
  });
}

// Forgets the truncations and episodes (keeps capacity).
template <class R>
void clearEvents(R& r) {
  forEachFinalArray(r, 1, [](auto& a, int) { a.clear(); });
  forEachEpisodeArray(r, 1, [](auto& a, int) { a.clear(); });
}

// A copy of environments: environment j of the source (one of src_envs) becomes environment
// dst_env[j] of the destination (one of dst_envs), or is left out when dst_env[j] < 0.
struct EnvCopy {
  int horizon = 0, obs_dim = 0, act_dim = 0;
  int src_envs = 0, dst_envs = 0;
  std::span<const int> dst_env;  // src_envs entries
  // What the episode lists number environments from: 0 in a Rollout, env_offset in a chunk (its
  // episodes name the actor's environment, not the chunk's).
  int src_episode_base = 0, dst_episode_base = 0;
  // Reward terms per episode on each side; a source with other terms keeps its returns, not its
  // term sums (zeros in the destination).
  int src_terms = 0, dst_terms = 0;
};

// Copies the per-step arrays of the mapped environments into dst's, which hold dst_envs
// environments already (resizeSteps). Consecutive environments that stay consecutive go in one
// memcpy per step and field (a chunk is one such run).
template <class Src, class Dst>
void copyEnvironmentSteps(const Src& src, Dst& dst, const EnvCopy& c) {
  forEachStepArrayOf(src, dst, c.obs_dim, c.act_dim, [&](const auto& from, auto& to, int width, int extra_rows) {
    using S = typename std::decay_t<decltype(from)>::value_type;
    using D = typename std::decay_t<decltype(to)>::value_type;
    static_assert(sizeof(S) == sizeof(D), "a field has one size in every stage");  // flags: uint8 here, int8 on the wire
    const int rows = c.horizon + extra_rows;
    for (int j = 0; j < c.src_envs;) {
      const int d = c.dst_env[j];
      if (d < 0) {
        ++j;
        continue;
      }
      int run = 1;
      while (j + run < c.src_envs && c.dst_env[j + run] == d + run) ++run;
      const std::size_t bytes = static_cast<std::size_t>(run) * width * sizeof(S);
      for (int t = 0; t < rows; ++t) {
        std::memcpy(&to[(static_cast<std::size_t>(t) * c.dst_envs + d) * width],
                    &from[(static_cast<std::size_t>(t) * c.src_envs + j) * width], bytes);
      }
      j += run;
    }
  });
}

// Appends the truncations and episodes of the mapped environments to dst's lists, renumbered to
// the destination's environments, in the source's order (a chunk's run of environments keeps the
// truncations ascending; a pool that is not in order is sorted when a batch is taken).
template <class Src, class Dst>
void appendEnvironmentEvents(const Src& src, Dst& dst, const EnvCopy& c) {
  const std::size_t od = static_cast<std::size_t>(c.obs_dim);
  for (std::size_t i = 0; i < src.final_index.size(); ++i) {
    const int t = src.final_index[i] / c.src_envs, j = src.final_index[i] % c.src_envs;
    const int d = c.dst_env[j];
    if (d < 0) continue;
    dst.final_index.push_back(static_cast<int32_t>(static_cast<int64_t>(t) * c.dst_envs + d));
    const float* o = &src.final_obs[i * od];
    dst.final_obs.insert(dst.final_obs.end(), o, o + od);
  }
  const bool terms_match = c.src_terms == c.dst_terms;
  for (std::size_t i = 0; i < src.episode_env.size(); ++i) {
    const int j = src.episode_env[i] - c.src_episode_base;
    const int d = c.dst_env[j];
    if (d < 0) continue;
    dst.episode_env.push_back(d + c.dst_episode_base);
    dst.episode_return.push_back(src.episode_return[i]);
    dst.episode_length.push_back(src.episode_length[i]);
    dst.episode_success.push_back(src.episode_success[i]);
    for (int k = 0; k < c.dst_terms; ++k)
      dst.episode_term_sums.push_back(terms_match ? src.episode_term_sums[i * c.src_terms + k] : 0.0f);
  }
}

// Puts the truncations back in ascending step order (the Rollout's invariant) after environments
// were gathered out of order. `order` and `obs` are the caller's scratch, kept between calls so
// that a steady run allocates nothing.
template <class R>
void sortFinals(R& r, int obs_dim, std::vector<std::pair<int32_t, int32_t>>& order, std::vector<float>& obs) {
  if (std::is_sorted(r.final_index.begin(), r.final_index.end())) return;
  const std::size_t n = r.final_index.size(), od = static_cast<std::size_t>(obs_dim);
  order.clear();
  for (std::size_t i = 0; i < n; ++i) order.emplace_back(r.final_index[i], static_cast<int32_t>(i));
  std::sort(order.begin(), order.end());
  obs.resize(n * od);
  for (std::size_t k = 0; k < n; ++k) {
    r.final_index[k] = order[k].first;
    std::memcpy(&obs[k * od], &r.final_obs[order[k].second * od], od * sizeof(float));
  }
  std::copy(obs.begin(), obs.end(), r.final_obs.begin());  // not a swap: each keeps its reserved capacity
}

}  // namespace masa::rollout
