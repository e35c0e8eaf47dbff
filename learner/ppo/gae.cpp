#include "learner/ppo/gae.hpp"

#include "common/core/check.hpp"

namespace masa::ppo {

template <typename S>
void computeGae(const GaeConfig& config, const StepMat<S>& rewards, const FlagMat& terminated,
                const FlagMat& truncated, const StepMat<S>& values, const StepMat<S>& truncation_values,
                const Vec<S>& bootstrap_values, StepMat<S>& advantages, StepMat<S>& returns) {
  const Eigen::Index T = rewards.rows(), E = rewards.cols();
  auto same = [&](const auto& m) { return m.rows() == T && m.cols() == E; };
  MASA_CHECK(same(terminated) && same(truncated) && same(values) && same(truncation_values) && same(advantages) &&
                 same(returns),
             "GAE inputs must all be " << T << " x " << E);
  MASA_CHECK(bootstrap_values.size() == E, "bootstrap values has " << bootstrap_values.size() << " entries, " << E
                                                                   << " envs");
  const S gamma = static_cast<S>(config.gamma);
  const S gamma_lambda = static_cast<S>(config.gamma * config.lambda);
  const S bootstrap_truncation = config.value_bootstrap ? S(1) : S(0);
  // Row t+1 of `advantages` holds A_(t+1) when row t is computed; the last row reads the bootstrap.
  for (Eigen::Index t = T - 1; t >= 0; --t) {
    const bool last = t == T - 1;
    for (Eigen::Index e = 0; e < E; ++e) {
      const S term = terminated(t, e) ? S(1) : S(0);
      const S trunc = truncated(t, e) && !terminated(t, e) ? S(1) : S(0);
      const S cont = (S(1) - term) * (S(1) - trunc);  // 1 when step t+1 continues this episode
      const S next_value = last ? bootstrap_values(e) : values(t + 1, e);
      const S next_adv = last ? S(0) : advantages(t + 1, e);
      // Multiplying by 0/1 masks rather than branching keeps the loop vectorizable; a masked
      // entry may hold anything finite (truncation_values off time-outs is never meaningful).
      const S tv = trunc > S(0) ? truncation_values(t, e) : S(0);
      const S delta = rewards(t, e) + gamma * (cont * next_value + bootstrap_truncation * trunc * tv) - values(t, e);
      advantages(t, e) = delta + gamma_lambda * cont * next_adv;
    }
  }
  returns = advantages + values;
}

template void computeGae<float>(const GaeConfig&, const StepMat<float>&, const FlagMat&, const FlagMat&,
                                const StepMat<float>&, const StepMat<float>&, const Vec<float>&, StepMat<float>&,
                                StepMat<float>&);
template void computeGae<double>(const GaeConfig&, const StepMat<double>&, const FlagMat&, const FlagMat&,
                                 const StepMat<double>&, const StepMat<double>&, const Vec<double>&, StepMat<double>&,
                                 StepMat<double>&);

}  // namespace masa::ppo
