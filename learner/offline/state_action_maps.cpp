#include "learner/offline/state_action_maps.hpp"

namespace masa::offline {

sym::SparseMap stateActionTransform(const sym::SymmetrySpec& spec, int i) {
  const int o = spec.obsDim(), a = spec.actDim();
  std::vector<sym::Triplet> t;
  const sym::SparseMap& to = spec.obsTransform(i);
  const sym::SparseMap& ta = spec.actTransform(i);
  for (int r = 0; r < o; ++r)
    for (int k = to.rowStart()[r]; k < to.rowStart()[r + 1]; ++k) t.push_back({r, to.colIndex()[k], to.values()[k]});
  for (int r = 0; r < a; ++r)
    for (int k = ta.rowStart()[r]; k < ta.rowStart()[r + 1]; ++k)
      t.push_back({o + r, o + ta.colIndex()[k], ta.values()[k]});
  return sym::SparseMap(o + a, o + a, t);
}

model::AgentMaps buildStateActionMaps(model::Method method, const sym::SymmetrySpec& spec) {
  MASA_CHECK(method == model::Method::kMasa || method == model::Method::kSa,
             "a state-action critic is built for masa or sa, not " << model::methodName(method));
  model::AgentMaps m;
  const int n = method == model::Method::kMasa ? spec.numAgents() : 1;
  m.num_agents = n;
  m.obs_dim = spec.obsDim() + spec.actDim();  // the critic's "observation" is the pair
  m.act_dim = 0;
  m.agent_input_dim = m.obs_dim;
  m.agent_output_dim = 0;
  m.input_constant = Eigen::MatrixXd::Zero(m.agent_input_dim, n);
  for (int i = 0; i < n; ++i) m.input.push_back(stateActionTransform(spec, i));
  m.pool = Eigen::MatrixXd::Constant(1, n, 1.0 / n);
  return m;
}

}  // namespace masa::offline
