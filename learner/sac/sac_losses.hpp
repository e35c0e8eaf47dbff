// The three losses of SAC with automatic entropy temperature (Haarnoja et al. 2018, "Soft
// Actor-Critic Algorithms and Applications"), on 1 x B rows; each returns its value and writes its
// gradient (the batch mean is taken inside: gradients carry the 1/B).
#pragma once

#include "common/core/types.hpp"

namespace masa::sac {

// Clipped double-Q soft target: y = R + discount * (min(Q1', Q2')(o', a') - alpha log pi(a' | o')),
// a' ~ pi(o'); R and discount are the replay's n-step sum and g^m (0 after a termination).
template <typename S>
void softQTarget(const ConstMatRef<S>& rewards, const ConstMatRef<S>& discount, const ConstMatRef<S>& min_q_next,
                 const ConstMatRef<S>& log_prob_next, S alpha, MatRef<S> target);

// Twin regression: L = sum_k mean_b (Q_k - y)^2 over the rows of q (2 x B); dq = dL/dq.
template <typename S>
S twinQLoss(const ConstMatRef<S>& q, const ConstMatRef<S>& target, MatRef<S> dq);

// Actor: L = mean_b (alpha log pi(a_b | o_b) - min(Q1, Q2)(o_b, a_b)), a reparameterized.
// Writes dL/dlog_prob and dL/dq for both rows of q (the smaller of the two gets -1/B; a tie goes
// to Q1).
template <typename S>
S actorLoss(const ConstMatRef<S>& log_prob, const ConstMatRef<S>& q, S alpha, MatRef<S> dlog_prob, MatRef<S> dq);

// Temperature: L = -alpha mean_b (log pi(a_b | o_b) + target_entropy), alpha = exp(log_alpha);
// returns L and writes dL/dlog_alpha. Descending it raises alpha while the policy's entropy
// (-log pi) is below the target and lowers it above.
template <typename S>
S temperatureLoss(S log_alpha, const ConstMatRef<S>& log_prob, S target_entropy, S& dlog_alpha);

}  // namespace masa::sac
