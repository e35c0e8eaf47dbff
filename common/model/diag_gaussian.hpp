// Diagonal Gaussian policy distribution: one log-std vector shared by the whole batch.
// Columns are samples (act_dim x B); per-sample results are 1 x B rows.
#pragma once

#include "common/core/types.hpp"

namespace masa::model::gaussian {

// log N(a | mean, diag(exp(log_std))^2) per column.
template <typename S>
void logProb(const ConstMatRef<S>& mean, const ConstVecRef<S>& log_std, const ConstMatRef<S>& action, MatRef<S> out);

// Gradients of sum_b dlogp_b * logp_b: dmean = dlogp_b (a - mu) / sigma^2 (overwritten),
// dlog_std += sum_b dlogp_b ((a - mu)^2 / sigma^2 - 1).
template <typename S>
void logProbBackward(const ConstMatRef<S>& mean, const ConstVecRef<S>& log_std, const ConstMatRef<S>& action,
                     const ConstMatRef<S>& dlogp, MatRef<S> dmean, VecRef<S> dlog_std);

// Entropy of one sample's distribution (identical for every column).
template <typename S>
S entropy(const ConstVecRef<S>& log_std);

// out = mean + exp(log_std) * eps, eps ~ N(0, I) drawn from rng in column order.
template <typename S>
void sample(const ConstMatRef<S>& mean, const ConstVecRef<S>& log_std, Rng& rng, MatRef<S> out);

// KL(old || new) per column. log_std_old is act x 1 (one behaviour policy for the whole batch) or
// act x B (one per sample: rollouts of several policy versions mixed in one batch).
template <typename S>
void kl(const ConstMatRef<S>& mean_old, const ConstMatRef<S>& log_std_old, const ConstMatRef<S>& mean_new,
        const ConstVecRef<S>& log_std_new, MatRef<S> out);

}  // namespace masa::model::gaussian
