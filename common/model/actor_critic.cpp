#include "common/model/actor_critic.hpp"

#include <istream>
#include <numeric>
#include <ostream>
#include <stdexcept>

#include "common/core/binary_io.hpp"
#include "common/nn/serialize.hpp"

namespace masa::model {
namespace {
constexpr char kMagic[8] = {'M', 'A', 'S', 'A', 'M', 'O', 'D', '1'};
}

std::string actionSquashName(ActionSquash s) { return s == ActionSquash::kTanh ? "tanh" : "none"; }

template <typename S>
ActorCritic<S>::ActorCritic(const sym::SymmetrySpec& spec, const ModelConfig& config)
    : spec_(spec),
      config_(config),
      maps_(buildAgentMaps(config.method, spec_)),
      policy_(params_, "policy", &maps_, config.policy_hidden, config.activation),
      log_std_(params_, "policy.log_std", logStdClasses(config.method, spec_)),
      critic_(params_, "critic", &maps_, config.critic_hidden, config.critic_head_hidden, config.activation),
      obs_norm_(spec_.obsDim()),
      value_norm_(1) {
  params_.finalize();
  symmetrizeNormalizer(obs_norm_, config.method, spec_);
  for (int i = 0; i < spec_.numAgents(); ++i) act_t_transpose_.push_back(spec_.actTransform(i).transpose());
}

template <typename S>
void symmetrizeNormalizer(RunningMeanStd<S>& norm, Method method, const sym::SymmetrySpec& spec) {
  if (method != Method::kMasa && method != Method::kSasa) return;
  std::vector<sym::SparseMap> t;
  for (int i = 0; i < spec.numAgents(); ++i) t.push_back(spec.obsTransform(i));
  norm.setSymmetry(t, spec.obsClasses());
}
template void symmetrizeNormalizer<float>(RunningMeanStd<float>&, Method, const sym::SymmetrySpec&);
template void symmetrizeNormalizer<double>(RunningMeanStd<double>&, Method, const sym::SymmetrySpec&);

std::vector<int> logStdClasses(Method method, const sym::SymmetrySpec& spec) {
  const int c = spec.actCentralDim(), s = spec.actLimbDim(), a = spec.actDim();
  std::vector<int> classes(a);
  switch (method) {
    case Method::kMasa:
      return spec.actClasses();
    case Method::kMa:
      // Parameter sharing without symmetry: one std per limb slot, each central joint its own.
      for (int d = 0; d < a; ++d) classes[d] = d < c ? d : c + (d - c) % s;
      return classes;
    case Method::kSa:
    case Method::kSasa:
      std::iota(classes.begin(), classes.end(), 0);
      return classes;
  }
  return classes;
}

template <typename S>
void ActorCritic<S>::initialize(Rng& rng) {
  policy_.initialize(rng, static_cast<S>(config_.policy_last_layer_scale));
  log_std_.initialize(static_cast<S>(config_.init_log_std));
  critic_.initialize(rng);
}

template <typename S>
void ActorCritic<S>::normalizeInput(const ConstMatRef<S>& raw_obs) {
  MASA_CHECK(raw_obs.rows() == obsDim(), "observation has " << raw_obs.rows() << " rows, expected " << obsDim());
  const Eigen::Index b = raw_obs.cols();
  if (obs_normalized_.cols() < b) obs_normalized_.resize(obsDim(), b);
  if (config_.normalize_obs)
    obs_norm_.normalize(raw_obs, obs_normalized_.leftCols(b));
  else
    obs_normalized_.leftCols(b) = raw_obs;
  batch_ = static_cast<int>(b);
}

template <typename S>
void ActorCritic<S>::forward(const ConstMatRef<S>& raw_obs) {
  normalizeInput(raw_obs);
  const auto obs = obs_normalized_.leftCols(batch_);
  mean_ptr_ = policy_.forward(obs).data();
  value_ptr_ = critic_.forward(obs).data();
  computeSymmetryLosses();
  backward_ready_ = true;
}

template <typename S>
Eigen::Map<const Mat<S>> ActorCritic<S>::mean() const {
  MASA_CHECK(mean_ptr_ != nullptr, "mean() before forward()");
  return Eigen::Map<const Mat<S>>(mean_ptr_, actDim(), batch_);
}

template <typename S>
Eigen::Map<const Mat<S>> ActorCritic<S>::value() const {
  MASA_CHECK(value_ptr_ != nullptr, "value() before forward()");
  return Eigen::Map<const Mat<S>>(value_ptr_, 1, batch_);
}

template <typename S>
void ActorCritic<S>::logStd(VecRef<S> out) const {
  log_std_.get(out);
}

template <typename S>
Eigen::Map<const Mat<S>> ActorCritic<S>::actMean(const ConstMatRef<S>& raw_obs) {
  normalizeInput(raw_obs);
  backward_ready_ = false;
  mean_ptr_ = value_ptr_ = nullptr;
  auto action = policy_.infer(obs_normalized_.leftCols(batch_));
  if (config_.squash == ActionSquash::kTanh) action.array() = action.array().tanh();
  return Eigen::Map<const Mat<S>>(action.data(), actDim(), batch_);
}

template <typename S>
Eigen::Map<const Mat<S>> ActorCritic<S>::criticValue(const ConstMatRef<S>& raw_obs) {
  normalizeInput(raw_obs);
  backward_ready_ = false;
  mean_ptr_ = value_ptr_ = nullptr;
  // The first B columns are V(o) for every method (SASA appends its orbit copies after them).
  const S* p = critic_.forward(obs_normalized_.leftCols(batch_)).data();
  return Eigen::Map<const Mat<S>>(p, 1, batch_);
}

// SASA: the orbit copies are the stack's agents. Copy 0 is o itself; copy i is T_i o.
//   L_pi = c_pi / (N-1) * mean_b sum_(i>0) ||T_i A(o) - A(T_i o)||^2
//   L_v  = c_v  / (N-1) * mean_b sum_(i>0) |V(o) - V(T_i o)|
template <typename S>
void ActorCritic<S>::computeSymmetryLosses() {
  sym_policy_loss_ = S(0);
  sym_value_loss_ = S(0);
  if (config_.method != Method::kSasa) return;
  const int n = spec_.numAgents(), b = batch_, a = actDim();
  const Eigen::Index nb = static_cast<Eigen::Index>(n) * b;
  const auto y = policy_.agentOutputs();  // a x N*B
  if (sym_dagent_.cols() < nb) sym_dagent_.resize(a, nb);
  if (sym_residual_.cols() < b) sym_residual_.resize(a, b);
  if (dvalues_.cols() < nb) dvalues_.resize(1, nb);
  auto dy = sym_dagent_.leftCols(nb);
  dy.setZero();
  auto r = sym_residual_.leftCols(b);
  const S wp = S(config_.sasa_policy_coef) / S(n - 1);
  const S wv = S(config_.sasa_value_coef) / S(n - 1);
  const Eigen::Map<const Mat<S>> v(value_ptr_, 1, nb);
  auto dv = dvalues_.leftCols(nb);
  dv.setZero();
  for (int i = 1; i < n; ++i) {
    const auto yi = y.middleCols(static_cast<Eigen::Index>(i) * b, b);
    spec_.actTransform(i).template apply<S>(y.leftCols(b), r);
    r -= yi;
    sym_policy_loss_ += wp * r.squaredNorm() / S(b);
    // d/dY_0 = wp * 2/B * T_i^T r ; d/dY_i = -wp * 2/B * r   (r scaled in place: no temporaries)
    r *= S(2) * wp / S(b);
    act_t_transpose_[i].template applyAdd<S>(r, dy.leftCols(b));
    dy.middleCols(static_cast<Eigen::Index>(i) * b, b) -= r;
    for (int k = 0; k < b; ++k) {
      const S diff = v(0, k) - v(0, static_cast<Eigen::Index>(i) * b + k);
      sym_value_loss_ += wv * std::abs(diff) / S(b);
      const S g = wv * (diff > S(0) ? S(1) : (diff < S(0) ? S(-1) : S(0))) / S(b);
      dv(0, k) += g;
      dv(0, static_cast<Eigen::Index>(i) * b + k) -= g;
    }
  }
}

template <typename S>
void ActorCritic<S>::backward(const ConstMatRef<S>& dmean, const ConstVecRef<S>& dlog_std, const ConstMatRef<S>& dvalue) {
  MASA_CHECK(backward_ready_, "backward() needs a forward() first (actMean/criticValue overwrite its caches)");
  MASA_CHECK(config_.squash == ActionSquash::kNone,
             "a squashed (tanh) policy acts only: its Gaussian is SAC's, PPO cannot train it");
  MASA_CHECK(dvalue.rows() == 1 && dvalue.cols() == batch_, "dvalue must be 1 x " << batch_);
  log_std_.backward(dlog_std);
  if (config_.method == Method::kSasa) {
    policy_.backward(dmean, &sym_dagent_);
    const Eigen::Index nb = static_cast<Eigen::Index>(spec_.numAgents()) * batch_;
    auto dv = dvalues_.leftCols(nb);
    dv.leftCols(batch_) += dvalue;
    critic_.backward(dv);
    dv.leftCols(batch_) -= dvalue;  // leave the cached symmetry gradient as computed by forward
  } else {
    policy_.backward(dmean);
    critic_.backward(dvalue);
  }
}

template <typename S>
void ActorCritic<S>::save(std::ostream& os) const {
  os.write(kMagic, sizeof kMagic);
  const std::string method = methodName(config_.method);
  const int32_t len = static_cast<int32_t>(method.size());
  io::writePod(os, len);
  os.write(method.data(), len);
  nn::saveParameters(params_, os);
  obs_norm_.save(os);
  value_norm_.save(os);
}

template <typename S>
void ActorCritic<S>::load(std::istream& is, const std::string& source_name) {
  char magic[8] = {};
  is.read(magic, sizeof magic);
  if (!is || std::string(magic, 8) != std::string(kMagic, 8))
    throw std::runtime_error(source_name + ": not a masa model (bad magic)");
  int32_t len = 0;
  if (!io::readPod(is, len) || len < 0 || len > 64) throw std::runtime_error(source_name + ": truncated or corrupt model header");
  std::string method(len, '\0');
  is.read(method.data(), len);
  if (method != methodName(config_.method))
    throw std::runtime_error(source_name + ": model was trained with method '" + method + "', this model is '" +
                             methodName(config_.method) + "'");
  nn::loadParameters(params_, is, source_name);
  try {
    obs_norm_.load(is);
    value_norm_.load(is);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(source_name + ": " + e.what());
  }
}

template class ActorCritic<float>;
template class ActorCritic<double>;

}  // namespace masa::model
