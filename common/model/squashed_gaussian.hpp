// SAC's action distribution: a = tanh(u), u = mean + exp(log_std) * eps, eps ~ N(0, I), with
//   log pi(a | o) = sum_d [ -eps_d^2 / 2 - log_std_d - log(2 pi) / 2 - log(1 - tanh(u_d)^2) ],
// the Gaussian density corrected by the Jacobian of tanh, where log(1 - tanh(u)^2) is computed as
// 2 (log 2 - u - softplus(-2u)) (exact, and finite where tanh(u) rounds to +-1).
// tanh is odd and acts per entry, so it commutes with every signed permutation T of the actions:
// with an equivariant mean and a log-std permuted with the actions, the squashed distribution is
// equivariant too (T a under T o is drawn as a under o, with the noise T eps).
// Columns are samples; every function takes act_dim x B matrices.
#pragma once

#include "common/core/types.hpp"

namespace masa::sac::squashed_gaussian {

// Draws eps (act_dim x B, column by column) from rng.
template <typename S>
void drawNoise(Rng& rng, MatRef<S> eps);

// Reparameterized sample: actions = tanh(mean + exp(log_std) * eps), log_prob (1 x B).
template <typename S>
void sample(const ConstMatRef<S>& mean, const ConstMatRef<S>& log_std, const ConstMatRef<S>& eps, MatRef<S> actions,
            MatRef<S> log_prob);

// Gradients through the sample above with eps held fixed: given dL/dactions and dL/dlog_prob,
// writes dL/dmean and dL/dlog_std. (d/du of -log(1 - tanh(u)^2) is 2 tanh(u).)
template <typename S>
void sampleBackward(const ConstMatRef<S>& log_std, const ConstMatRef<S>& eps, const ConstMatRef<S>& actions,
                    const ConstMatRef<S>& dactions, const ConstMatRef<S>& dlog_prob, MatRef<S> dmean,
                    MatRef<S> dlog_std);

}  // namespace masa::sac::squashed_gaussian
