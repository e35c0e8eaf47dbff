#include "common/rollout/rollout.hpp"

#include <algorithm>

#include "common/core/check.hpp"
#include "common/rollout/rollout_fields.hpp"

namespace masa::rollout {

void Rollout::allocate(int e, int t, int od, int ad, const std::vector<std::string>& names) {
  MASA_CHECK(e > 0 && t > 0 && od > 0 && ad > 0,
             "rollout shape must be positive: E=" << e << " T=" << t << " obs=" << od << " act=" << ad);
  if (e == num_envs && t == horizon && od == obs_dim && ad == act_dim && names == term_names) {
    return;
  }
  num_envs = e;
  horizon = t;
  obs_dim = od;
  act_dim = ad;
  term_names = names;
  const std::size_t steps = static_cast<std::size_t>(t) * e;
  // Every array from the one list of the rollout's fields (rollout_fields.hpp): zero-filled steps,
  // event lists reserved for one event per step, so adding never allocates.
  forEachStepArray(*this, od, ad, [&](auto& a, int width, int extra_rows) { a.assign((steps + extra_rows * e) * width, 0); });
  env_log_std.assign(static_cast<std::size_t>(e) * ad, 0.0f);
  clearEvents();
  forEachFinalArray(*this, od, [&](auto& a, int width) { a.reserve(steps * width); });
  forEachEpisodeArray(*this, numTerms(), [&](auto& a, int width) { a.reserve(steps * width); });
}

void Rollout::clearEvents() { rollout::clearEvents(*this); }

void Rollout::addFinal(int t, int e, const float* pre_reset_obs) {
  MASA_CHECK(t >= 0 && t < horizon && e >= 0 && e < num_envs, "final step (" << t << ", " << e << ") out of range");
  const int idx = static_cast<int>(step(t, e));
  MASA_CHECK(final_index.empty() || final_index.back() < idx, "finals must be added in ascending step order");
  final_index.push_back(idx);
  final_obs.insert(final_obs.end(), pre_reset_obs, pre_reset_obs + obs_dim);
}

void Rollout::setLogStd(const float* log_std) {
  for (int e = 0; e < num_envs; ++e) std::copy_n(log_std, act_dim, logStdOf(e));
}

void Rollout::addEpisode(int e, float ret, int length, int8_t success, const float* term_sums) {
  MASA_CHECK(e >= 0 && e < num_envs, "episode env " << e << " out of range");
  episode_env.push_back(e);
  episode_return.push_back(ret);
  episode_length.push_back(length);
  episode_success.push_back(success);
  if (numTerms() > 0) episode_term_sums.insert(episode_term_sums.end(), term_sums, term_sums + numTerms());
}

}  // namespace masa::rollout
