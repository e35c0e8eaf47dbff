// Keeps a model's learned log-std parameters inside [lo, hi] (IQL's policy bounds them to
// [-5, 2]): with a likelihood loss on near-deterministic data the std would otherwise shrink
// without limit and the log-likelihood's gradients with it grow without limit.
#pragma once

#include "common/model/actor_critic.hpp"

namespace masa::offline {

template <typename S>
void clampLogStd(model::ActorCritic<S>& model, S lo, S hi);

}  // namespace masa::offline
