#include "learner/sac/sac_critic_maps.hpp"

#include "learner/offline/state_action_maps.hpp"

namespace masa::sac {

model::AgentMaps twinQMaps(model::Method method, const sym::SymmetrySpec& spec) {
  switch (method) {
    case model::Method::kMasa: return offline::buildStateActionMaps(model::Method::kMasa, spec);
    case model::Method::kSa:
    case model::Method::kSasa: return offline::buildStateActionMaps(model::Method::kSa, spec);
    case model::Method::kMa: break;
  }
  const int n = spec.numAgents(), pair = spec.obsDim() + spec.actDim();
  model::AgentMaps m;
  m.num_agents = n;
  m.obs_dim = pair;
  m.act_dim = 0;
  m.agent_input_dim = pair + n;
  m.agent_output_dim = 0;
  m.input_constant = Eigen::MatrixXd::Zero(m.agent_input_dim, n);
  std::vector<sym::Triplet> pass;
  for (int j = 0; j < pair; ++j) pass.push_back({j, j, 1.0});
  const sym::SparseMap in(m.agent_input_dim, pair, pass);
  for (int i = 0; i < n; ++i) {
    m.input.push_back(in);
    m.input_constant(pair + i, i) = 1.0;
  }
  m.pool = Eigen::MatrixXd::Constant(1, n, 1.0 / n);
  return m;
}

}  // namespace masa::sac
