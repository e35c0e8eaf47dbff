// Adam on a flat ParameterSet (or one contiguous range of it), plus global gradient-norm clipping.
#pragma once

#include <iosfwd>

#include "common/core/types.hpp"
#include "common/nn/parameter_set.hpp"

namespace masa::nn {

template <typename S>
struct AdamConfig {
  S lr = S(3e-4);
  S beta1 = S(0.9);
  S beta2 = S(0.999);
  S eps = S(1e-8);
};

template <typename S>
class Adam {
 public:
  Adam(ParameterSet<S>& params, AdamConfig<S> config = {});
  // Steps only the values [begin, end): parts of one model trained with their own rates (IQL's
  // actor and value function share an ActorCritic's parameter set, policy first).
  Adam(ParameterSet<S>& params, AdamConfig<S> config, int begin, int end);
  // One update from params.grads(); uses config().lr, which callers may change between steps.
  void step();
  AdamConfig<S>& config() { return config_; }
  const AdamConfig<S>& config() const { return config_; }
  long long stepCount() const { return t_; }

  // Optimizer state (moments and step counter) for checkpoints; binary, with size checks.
  void save(std::ostream& os) const;
  void load(std::istream& is);  // throws std::runtime_error on size mismatch or truncated stream

 private:
  ParameterSet<S>* params_;
  AdamConfig<S> config_;
  int begin_ = 0, end_ = 0;
  Vec<S> m_, v_;
  long long t_ = 0;
};

// Scales grads so that their global L2 norm is at most max_norm; returns the norm before scaling.
template <typename S>
S clipGradNorm(ParameterSet<S>& params, S max_norm);

}  // namespace masa::nn
