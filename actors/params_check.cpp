#include "actors/params_check.hpp"

#include <algorithm>
#include <cmath>

namespace masa::actor {

std::optional<std::string> ParamsCheck::refusal(const masa::lcmt_policy_params& m, int64_t newest) const {
  const ParamsExpectation& x = expected_;
  const int64_t base = std::max<int64_t>(newest, 0);
  if (m.version > newest && m.version - base > x.max_version_step)
    return "more than " + std::to_string(x.max_version_step) + " versions ahead of " + std::to_string(base);
  if (m.task != x.task) return "task '" + m.task + "', this actor runs '" + x.task + "'";
  if (m.method != x.method) return "method '" + m.method + "', this actor builds '" + x.method + "'";
  const int n = m.num_params;
  if (n != x.model_param_count && n != x.policy_param_count)
    return "num_params " + std::to_string(n) + ", expected " + std::to_string(x.policy_param_count) + " (policy) or " +
           std::to_string(x.model_param_count) + " (whole model)";
  if (static_cast<int>(m.params.size()) != n) return "params array length differs from num_params";
  // obs_dim 0: the learner does not normalize; the actor's normalizer stays at identity.
  if (m.obs_dim != 0 && m.obs_dim != x.obs_dim)
    return "obs_dim " + std::to_string(m.obs_dim) + ", expected " + std::to_string(x.obs_dim);
  if (static_cast<int>(m.obs_mean.size()) != m.obs_dim || static_cast<int>(m.obs_std.size()) != m.obs_dim)
    return "normalizer arrays differ from obs_dim";
  for (float v : m.params)
    if (!std::isfinite(v)) return "non-finite parameter";
  for (int d = 0; d < m.obs_dim; ++d)
    if (!std::isfinite(m.obs_mean[d]) || !std::isfinite(m.obs_std[d]) || !(m.obs_std[d] > 0.0f))
      return "bad normalizer entry " + std::to_string(d);
  return std::nullopt;
}

}  // namespace masa::actor
