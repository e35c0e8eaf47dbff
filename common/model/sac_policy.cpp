#include "common/model/sac_policy.hpp"

#include <cmath>
#include <istream>
#include <ostream>
#include <stdexcept>

#include "common/core/binary_io.hpp"
#include "common/model/actor_critic.hpp"
#include "common/nn/serialize.hpp"
#include "common/model/squashed_gaussian.hpp"

namespace masa::sac {
namespace {

using sym::SparseMap;
using sym::Triplet;

// m (+) |m|: rows and columns doubled, the second block with the absolute values of the first.
SparseMap withUnsignedCopy(const SparseMap& m) {
  std::vector<Triplet> t;
  for (int r = 0; r < m.rows(); ++r)
    for (int k = m.rowStart()[r]; k < m.rowStart()[r + 1]; ++k) {
      t.push_back({r, m.colIndex()[k], m.values()[k]});
      t.push_back({m.rows() + r, m.cols() + m.colIndex()[k], std::abs(m.values()[k])});
    }
  return SparseMap(2 * m.rows(), 2 * m.cols(), t);
}

void checkSignedPermutation(const SparseMap& m, int i) {
  for (int r = 0; r < m.rows(); ++r) {
    const int n = m.rowStart()[r + 1] - m.rowStart()[r];
    if (n != 1 || std::abs(std::abs(m.values()[m.rowStart()[r]]) - 1.0) > 1e-12)
      throw std::invalid_argument("action transform T_" + std::to_string(i) + " row " + std::to_string(r) +
                                  " is not a signed permutation: the SAC policy's log-std needs |T| to act as T");
  }
}

}  // namespace

model::AgentMaps meanAndLogStdMaps(model::Method method, const sym::SymmetrySpec& spec) {
  for (int i = 0; i < spec.numAgents(); ++i) checkSignedPermutation(spec.actTransform(i), i);
  model::AgentMaps m = model::buildAgentMaps(method, spec);
  for (auto& out : m.output) out = withUnsignedCopy(out);
  m.act_dim *= 2;
  m.agent_output_dim *= 2;
  return m;
}

template <typename S>
SacPolicy<S>::SacPolicy(const sym::SymmetrySpec& spec, const SacPolicyShape& shape)
    : spec_(spec),
      shape_(shape),
      maps_(meanAndLogStdMaps(shape.method, spec_)),
      act_dim_(spec_.actDim()),
      net_(params_, "sac_policy", &maps_, shape.hidden, shape.activation),
      obs_norm_(spec_.obsDim()) {
  MASA_CHECK(shape.log_std_min < shape.log_std_max, "log-std bounds are empty");
  params_.finalize();
  model::symmetrizeNormalizer(obs_norm_, shape.method, spec_);
  if (shape.method == model::Method::kSasa)
    for (int i = 0; i < spec_.numAgents(); ++i) {
      sym_t_.push_back(withUnsignedCopy(spec_.actTransform(i)));
      sym_t_transpose_.push_back(sym_t_.back().transpose());
    }
}

template <typename S>
void SacPolicy<S>::initialize(Rng& rng, S last_layer_scale) {
  net_.initialize(rng, last_layer_scale);
}

template <typename S>
void SacPolicy<S>::normalize(const ConstMatRef<S>& raw, Mat<S>& out) const {
  out.resize(raw.rows(), raw.cols());
  if (normalize_) obs_norm_.normalize(raw, out);
  else out = raw;
}

template <typename S>
void SacPolicy<S>::forward(const ConstMatRef<S>& obs_n) {
  batch_ = static_cast<int>(obs_n.cols());
  out_ = net_.forward(obs_n);
  const S lo = static_cast<S>(shape_.log_std_min), half = static_cast<S>(0.5 * (shape_.log_std_max - shape_.log_std_min));
  log_std_ = (lo + half * (out_.bottomRows(act_dim_).array().tanh() + S(1))).matrix();
  symmetryLossForward();
}

// SASA: L = c / (N-1) * mean_b sum_(i>0) ||T'_i y_0 - y_i||^2 on the copies' [mean; raw log-std].
template <typename S>
void SacPolicy<S>::symmetryLossForward() {
  sym_loss_ = S(0);
  if (shape_.method != model::Method::kSasa) return;
  const int n = spec_.numAgents(), b = batch_, a2 = 2 * act_dim_;
  const Eigen::Index nb = static_cast<Eigen::Index>(n) * b;
  const auto y = net_.agentOutputs();  // 2A x N*B
  sym_dagent_.setZero(a2, nb);
  sym_residual_.resize(a2, b);
  const S w = static_cast<S>(shape_.sasa_coef) / S(n - 1);
  for (int i = 1; i < n; ++i) {
    sym_t_[i].template apply<S>(y.leftCols(b), sym_residual_);
    sym_residual_ -= y.middleCols(static_cast<Eigen::Index>(i) * b, b);
    sym_loss_ += w * sym_residual_.squaredNorm() / S(b);
    sym_residual_ *= S(2) * w / S(b);
    sym_t_transpose_[i].template applyAdd<S>(sym_residual_, sym_dagent_.leftCols(b));
    sym_dagent_.middleCols(static_cast<Eigen::Index>(i) * b, b) -= sym_residual_;
  }
}

template <typename S>
void SacPolicy<S>::backward(const ConstMatRef<S>& dmean, const ConstMatRef<S>& dlog_std) {
  MASA_CHECK(dmean.rows() == act_dim_ && dmean.cols() == batch_ && dlog_std.rows() == act_dim_ &&
                 dlog_std.cols() == batch_,
             "policy gradients must be " << act_dim_ << " x " << batch_);
  dout_.resize(2 * act_dim_, batch_);
  dout_.topRows(act_dim_) = dmean;
  // d log_std / d raw = (hi - lo) / 2 (1 - tanh(raw)^2)
  const S half = static_cast<S>(0.5 * (shape_.log_std_max - shape_.log_std_min));
  dout_.bottomRows(act_dim_) =
      (dlog_std.array() * half * (S(1) - out_.bottomRows(act_dim_).array().tanh().square())).matrix();
  net_.backward(dout_, shape_.method == model::Method::kSasa ? &sym_dagent_ : nullptr);
}

template <typename S>
void SacPolicy<S>::actDeterministic(const ConstMatRef<S>& raw_obs, MatRef<S> actions) {
  normalize(raw_obs, scratch_);
  const auto out = net_.infer(scratch_);
  actions = out.topRows(act_dim_).array().tanh().matrix();
}

template <typename S>
void SacPolicy<S>::actStochastic(const ConstMatRef<S>& raw_obs, Rng& rng, MatRef<S> actions) {
  normalize(raw_obs, scratch_);
  forward(scratch_);
  eps_.resize(act_dim_, batch_);
  logp_.resize(1, batch_);
  squashed_gaussian::drawNoise<S>(rng, eps_);
  squashed_gaussian::sample<S>(mean(), logStd(), eps_, actions, logp_);
}

namespace {
constexpr char kMagic[8] = {'M', 'A', 'S', 'A', 'S', 'A', 'C', '1'};
}

template <typename S>
void SacPolicy<S>::save(std::ostream& os) const {
  os.write(kMagic, sizeof kMagic);
  const int32_t method = static_cast<int32_t>(shape_.method), normalize = normalize_ ? 1 : 0;
  io::writePod(os, method);
  io::writePod(os, normalize);
  nn::saveParameters(params_, os);
  obs_norm_.save(os);
}

template <typename S>
void SacPolicy<S>::load(std::istream& is, const std::string& source_name) {
  char magic[8] = {};
  is.read(magic, sizeof magic);
  if (!is || std::string(magic, 8) != std::string(kMagic, 8))
    throw std::runtime_error(source_name + ": not a masa SAC policy (bad magic)");
  int32_t method = -1, normalize = 0;
  if (!io::readPod(is, method) || !io::readPod(is, normalize)) throw std::runtime_error(source_name + ": truncated SAC policy");
  if (method != static_cast<int32_t>(shape_.method))
    throw std::runtime_error(source_name + ": SAC policy of another method than " + model::methodName(shape_.method));
  nn::loadParameters(params_, is, source_name);
  obs_norm_.load(is);
  normalize_ = normalize != 0;
}

template class SacPolicy<float>;
template class SacPolicy<double>;

}  // namespace masa::sac
