// How a method feeds one observation to its agents and gathers their outputs, as linear maps.
//
// Every method runs ONE shared network on a stack of per-agent inputs (agents along the batch
// axis, so one GEMM serves them all):
//   x_i = In_i o + c_i          (agent input; c_i is a constant column, the one-hot id for MA)
//   y_i = Phi(x_i)              (shared network)
//   a   = sum_i Out_i y_i       (the robot's action)
// MASA: In_i = T_i, Out_i = W T_i^-1 E (E embeds (a_c, a_s) as central + limb 0, W averages the
// central rows over agents). MA: In_i = [I; 0], c_i = e_i, Out_i puts a_s into limb i and averages
// a_c. SA: one agent, identities. SASA: the SA net on the orbit copies In_i = T_i, with the action
// read from copy 0 (Out_0 = I, Out_i = 0) and the symmetry losses comparing the copies.
// Critics use the same inputs and pool agent features with fixed weights (AgentMaps::pool).
#pragma once

#include <vector>

#include "common/model/method.hpp"
#include "common/symmetry/symmetry_spec.hpp"

namespace masa::model {

struct AgentMaps {
  int num_agents = 1;
  int obs_dim = 0;
  int act_dim = 0;
  int agent_input_dim = 0;
  int agent_output_dim = 0;
  std::vector<sym::SparseMap> input;         // agent_input_dim x obs_dim, one per agent
  Eigen::MatrixXd input_constant;            // agent_input_dim x num_agents (zero if unused)
  std::vector<sym::SparseMap> output;        // act_dim x agent_output_dim, one per agent
  Eigen::MatrixXd pool;                      // critic: num_pooled x num_agents weights on agent features

  int numPooled() const { return static_cast<int>(pool.rows()); }
};

AgentMaps buildAgentMaps(Method method, const sym::SymmetrySpec& spec);

}  // namespace masa::model
