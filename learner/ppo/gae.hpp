// Generalized advantage estimation (Schulman et al.) over a T x E batch, with time-outs kept apart
// from terminations:
//   terminated step:  delta = r - V(s_t)                      (nothing after the end)
//   truncated step:   delta = r + gamma V(final obs) - V(s_t)  (value_bootstrap; else r - V(s_t))
//   other step:       delta = r + gamma V(s_(t+1)) - V(s_t)    (V(bootstrap obs) after step T-1)
//   A_t = delta_t + gamma lambda A_(t+1), the recursion cut at terminated and truncated steps:
//   the next row of a truncated env is already the next episode.
// A step flagged both terminated and truncated counts as terminated. Values are in real units.
//
// Deliberately unlike rl_games: on a time-out rl_games adds gamma * V(s_t) (the value of the
// observation BEFORE the step, the only one it keeps) to the reward. We bootstrap from the value
// of the true final observation the actor sends with the step, which is what the truncated
// return's tail actually is; the two agree only when V changes little in one step.
#pragma once

#include "common/core/types.hpp"
#include "common/rollout/rollout_buffer.hpp"

namespace masa::ppo {

// PPO learns from the learner's batch: the rollout's layout with its views (common/rollout).
using rollout::FinalObsEntry;
using rollout::FlagMat;
using rollout::RolloutBuffer;
using rollout::StepMat;

struct GaeConfig {
  double gamma = 0.99;
  double lambda = 0.95;  // rl_games' tau
  bool value_bootstrap = true;
};

// rewards, values, truncation_values, advantages, returns: T x E. truncation_values(t, e) is
// V(final obs of step (t, e)), read only where truncated. bootstrap_values: E, V(bootstrap obs).
// Writes advantages and returns = advantages + values.
template <typename S>
void computeGae(const GaeConfig& config, const StepMat<S>& rewards, const FlagMat& terminated,
                const FlagMat& truncated, const StepMat<S>& values, const StepMat<S>& truncation_values,
                const Vec<S>& bootstrap_values, StepMat<S>& advantages, StepMat<S>& returns);

}  // namespace masa::ppo
