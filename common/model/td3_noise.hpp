// TD3's noisy actions (Fujimoto et al. 2018, "Addressing Function Approximation Error in
// Actor-Critic Methods") on the deterministic policy tanh(mean):
//   a = clip(tanh(mean) + clip(sigma eps, -c, c), -1, 1),  eps ~ N(0, I)
// Target policy smoothing uses sigma = td3_policy_noise, c = td3_noise_clip; collection uses
// sigma = td3_exploration_noise and no clip on the noise (c = infinity). tanh and both clips act
// entry by entry and are odd, so they commute with every signed permutation T: with an
// equivariant mean, T a under T o is drawn as a under o, with the noise T eps.
#pragma once

#include "common/core/types.hpp"

namespace masa::sac::td3 {

// Writes clip(tanh(mean) + clip(sigma eps, -noise_clip, noise_clip), -1, 1) (act_dim x B).
template <typename S>
void noisyActions(const ConstMatRef<S>& mean, const ConstMatRef<S>& eps, S sigma, S noise_clip, MatRef<S> actions);

}  // namespace masa::sac::td3
