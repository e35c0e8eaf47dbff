// Agent maps (common/model/agent_maps.hpp) for a critic of state-action pairs x = [o; a].
//
// MASA: agent i reads the joint image J_i x = [T_i o; T_i^a a] and the features are averaged over
// agents, so Q(T_j o, T_j^a a) = Q(o, a) exactly (J_i J_j = J_(i+j), the mean runs over the same
// orbit). SA (and SASA-data): one agent reading x itself, a plain MLP on [o; a].
#pragma once

#include "common/model/agent_maps.hpp"

namespace masa::offline {

// Input maps and pooling only (a critic has no action outputs). Methods other than sa and masa are
// not offline methods and throw std::invalid_argument.
model::AgentMaps buildStateActionMaps(model::Method method, const sym::SymmetrySpec& spec);

// J_i = T_i (+) T_i^a: (obs_dim + act_dim) square, block diagonal.
sym::SparseMap stateActionTransform(const sym::SymmetrySpec& spec, int i);

}  // namespace masa::offline
