#include "common/model/agent_maps.hpp"

namespace masa::model {
namespace {

using sym::SparseMap;
using sym::Triplet;

// E: (a_c, a_s) -> full action with a_s in limb block `limb` (and other limbs zero).
SparseMap embedAgentAction(const sym::SymmetrySpec& spec, int limb, double central_weight) {
  const int c = spec.actCentralDim(), s = spec.actLimbDim();
  std::vector<Triplet> t;
  for (int j = 0; j < c; ++j) t.push_back({j, j, central_weight});
  for (int j = 0; j < s; ++j) t.push_back({c + limb * s + j, c + j, 1.0});
  return SparseMap(spec.actDim(), c + s, t);
}

// Scales the central rows of a map with act_dim rows.
SparseMap scaleCentralRows(const SparseMap& m, int central_dim, double w) {
  std::vector<Triplet> t;
  for (int r = 0; r < m.rows(); ++r)
    for (int k = m.rowStart()[r]; k < m.rowStart()[r + 1]; ++k)
      t.push_back({r, m.colIndex()[k], r < central_dim ? w * m.values()[k] : m.values()[k]});
  return SparseMap(m.rows(), m.cols(), t);
}

AgentMaps masaMaps(const sym::SymmetrySpec& spec) {
  AgentMaps m;
  const int n = spec.numAgents();
  m.num_agents = n;
  m.obs_dim = spec.obsDim();
  m.act_dim = spec.actDim();
  m.agent_input_dim = spec.obsDim();
  m.agent_output_dim = spec.actCentralDim() + spec.actLimbDim();
  m.input_constant = Eigen::MatrixXd::Zero(m.agent_input_dim, n);
  const SparseMap e0 = embedAgentAction(spec, 0, 1.0);
  for (int i = 0; i < n; ++i) {
    m.input.push_back(spec.obsTransform(i));
    // Agent i's limb output lands in limb i because T_i^-1 moves block 0 to block i.
    m.output.push_back(scaleCentralRows(spec.actInverse(i).compose(e0), spec.actCentralDim(), 1.0 / n));
  }
  m.pool = Eigen::MatrixXd::Constant(1, n, 1.0 / n);
  return m;
}

AgentMaps maMaps(const sym::SymmetrySpec& spec) {
  AgentMaps m;
  const int n = spec.numAgents();
  m.num_agents = n;
  m.obs_dim = spec.obsDim();
  m.act_dim = spec.actDim();
  m.agent_input_dim = spec.obsDim() + n;
  m.agent_output_dim = spec.actCentralDim() + spec.actLimbDim();
  m.input_constant = Eigen::MatrixXd::Zero(m.agent_input_dim, n);
  std::vector<Triplet> pass;
  for (int j = 0; j < spec.obsDim(); ++j) pass.push_back({j, j, 1.0});
  const SparseMap in(m.agent_input_dim, spec.obsDim(), pass);
  for (int i = 0; i < n; ++i) {
    m.input.push_back(in);
    m.input_constant(spec.obsDim() + i, i) = 1.0;
    m.output.push_back(embedAgentAction(spec, i, 1.0 / n));
  }
  m.pool = Eigen::MatrixXd::Constant(1, n, 1.0 / n);
  return m;
}

AgentMaps saMaps(const sym::SymmetrySpec& spec, bool with_orbit) {
  AgentMaps m;
  const int n = with_orbit ? spec.numAgents() : 1;
  m.num_agents = n;
  m.obs_dim = spec.obsDim();
  m.act_dim = spec.actDim();
  m.agent_input_dim = spec.obsDim();
  m.agent_output_dim = spec.actDim();
  m.input_constant = Eigen::MatrixXd::Zero(m.agent_input_dim, n);
  for (int i = 0; i < n; ++i) {
    m.input.push_back(spec.obsTransform(i));
    m.output.push_back(i == 0 ? SparseMap::identity(spec.actDim()) : SparseMap(spec.actDim(), spec.actDim(), {}));
  }
  // SASA keeps one value per orbit copy (the losses compare them); SA has a single copy.
  m.pool = Eigen::MatrixXd::Identity(n, n);
  return m;
}

}  // namespace

AgentMaps buildAgentMaps(Method method, const sym::SymmetrySpec& spec) {
  switch (method) {
    case Method::kMasa: return masaMaps(spec);
    case Method::kMa: return maMaps(spec);
    case Method::kSa: return saMaps(spec, false);
    case Method::kSasa: return saMaps(spec, true);
  }
  MASA_CHECK(false, "unhandled method");
  return {};
}

}  // namespace masa::model
