// The three losses of Implicit Q-Learning (Kostrikov et al.), on 1 x B rows, each returning its
// value and writing its gradient (the batch mean is taken inside: gradients carry the 1/B).
#pragma once

#include "common/core/types.hpp"

namespace masa::offline {

// Expectile regression of V towards Q: L = mean_b |tau - 1(u_b < 0)| u_b^2, u = target - value.
// tau > 0.5 weighs V below Q more than above, so V approaches an upper expectile of Q over the
// dataset's actions: a soft maximum that never queries an action outside the data (tau = 0.5 is
// half the mean squared error).
template <typename S>
S expectileLoss(const ConstMatRef<S>& value, const ConstMatRef<S>& target, S tau, MatRef<S> dvalue);

// Advantage weights of the policy extraction: w = min(exp(beta * advantage), max_weight).
template <typename S>
void advantageWeights(const ConstMatRef<S>& advantage, S beta, S max_weight, MatRef<S> weights);

// Twin TD regression: L = sum_k mean_b (Q_k - y)^2 over the rows of q (2 x B); dq = dL/dq.
template <typename S>
S tdLoss(const ConstMatRef<S>& q, const ConstMatRef<S>& target, MatRef<S> dq);

}  // namespace masa::offline
