// The maps of SAC's twin Q (learner/offline/twin_q.hpp) for each of the four methods:
//   MASA: agent i reads J_i [o; a] = [T_i o; T_i a], features averaged: Q(T_i o, T_i a) = Q(o, a)
//         exactly (learner/offline/state_action_maps.hpp);
//   SA:   one agent reading [o; a], a plain MLP;
//   SASA: as SA (its symmetry losses are on the policy, sac_policy.hpp);
//   MA:   every agent reads [o; a; e_i] with its one-hot id e_i, features averaged (parameter
//         sharing without symmetry, as MA's critic online).
#pragma once

#include "common/model/agent_maps.hpp"

namespace masa::sac {

model::AgentMaps twinQMaps(model::Method method, const sym::SymmetrySpec& spec);

}  // namespace masa::sac
