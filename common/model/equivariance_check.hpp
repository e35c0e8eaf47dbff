// Measures how far a model is from the symmetry MASA guarantees, on given inputs:
//   A(T_i o) = T_i A(o),  log pi(T_i a | T_i o) = log pi(a | o),  V(T_i o) = V(o)
// through the whole pipeline (normalizer, policy mean, tied std, log-prob, critic).
// MASA should give rounding-level errors; SA and MA (no symmetry built in) give large ones.
#pragma once

#include "common/model/actor_critic.hpp"

namespace masa::model {

struct EquivarianceReport {
  double mean_error = 0;    // max_i,b,d |A(T_i o) - T_i A(o)| / (1 + |T_i A(o)|)
  double logp_error = 0;    // max_i,b |log pi(T_i a|T_i o) - log pi(a|o)| / (1 + |log pi(a|o)|)
  double value_error = 0;   // max_i,b |V(T_i o) - V(o)| / (1 + |V(o)|)
  double worst() const { return std::max(mean_error, std::max(logp_error, value_error)); }
};

template <typename S>
EquivarianceReport checkEquivariance(ActorCritic<S>& model, const ConstMatRef<S>& obs, const ConstMatRef<S>& actions);

}  // namespace masa::model
