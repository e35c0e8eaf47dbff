// SAC's policy for the four methods: one shared network Phi (common/model/shared_agent_policy.hpp)
// whose every agent outputs both a mean and a raw log-std for its share of the action. The two
// halves are gathered by the method's output maps: the mean by Out_i, the log-std by |Out_i|
// (the same map with its signs dropped). For MASA, Out_i = W T_i^-1 E, so the mean is equivariant,
// mean(T_j o) = T_j mean(o), and the log-std is permuted with the agents and limbs without signs,
// log_std(T_j o) = |T_j| log_std(o): the squashed Gaussian of squashed_gaussian.hpp is then exactly
// equivariant. SA: one agent; SASA: SA on the orbit copies with the symmetry loss of both halves
// (||T'_i y(o) - y(T_i o)||^2, T'_i = T_i (+) |T_i|); MA: one-hot agents, no symmetry.
// The log-std is bounded smoothly: log_std = lo + (hi - lo) (tanh(raw) + 1) / 2.
// The observation normalizer (orbit-symmetric for MASA and SASA) lives here so that a saved policy
// carries it; the learner fits it once and holds it fixed (Q reads the same normalized inputs).
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "common/model/agent_maps.hpp"
#include "common/model/running_mean_std.hpp"
#include "common/model/shared_agent_policy.hpp"
#include "common/nn/parameter_set.hpp"

namespace masa::sac {

struct SacPolicyShape {
  model::Method method = model::Method::kMasa;
  std::vector<int> hidden{256, 256};
  nn::Activation activation = nn::Activation::kElu;
  double log_std_min = -5.0, log_std_max = 2.0;
  double sasa_coef = 1.0;  // weight of SASA's symmetry loss
};

// The method's agent maps with every agent's output doubled to [mean part; log-std part] and each
// output map Out_i replaced by Out_i (+) |Out_i|. Throws unless every action transform is a signed
// permutation (what |T| being a representation needs).
model::AgentMaps meanAndLogStdMaps(model::Method method, const sym::SymmetrySpec& spec);

template <typename S>
class SacPolicy {
 public:
  SacPolicy(const sym::SymmetrySpec& spec, const SacPolicyShape& shape);
  SacPolicy(const SacPolicy&) = delete;
  SacPolicy& operator=(const SacPolicy&) = delete;

  void initialize(Rng& rng, S last_layer_scale = S(0.01));
  const SacPolicyShape& shape() const { return shape_; }
  int obsDim() const { return maps_.obs_dim; }
  int actDim() const { return act_dim_; }
  nn::ParameterSet<S>& params() { return params_; }
  const nn::ParameterSet<S>& params() const { return params_; }
  model::RunningMeanStd<S>& obsNormalizer() { return obs_norm_; }
  const model::RunningMeanStd<S>& obsNormalizer() const { return obs_norm_; }
  bool normalizes() const { return normalize_; }
  void setNormalizes(bool on) { normalize_ = on; }
  // raw -> the networks' input (identity while normalizes() is false).
  void normalize(const ConstMatRef<S>& raw, Mat<S>& out) const;

  // On normalized observations (obs_dim x B); caches for backward. Views valid until the next call.
  void forward(const ConstMatRef<S>& obs_n);
  Eigen::Block<const Mat<S>> mean() const { return out_.block(0, 0, act_dim_, batch_); }
  Eigen::Block<const Mat<S>> logStd() const { return log_std_.block(0, 0, act_dim_, batch_); }
  // SASA's symmetry loss of the last forward, weighted (0 for other methods).
  S symmetryLoss() const { return sym_loss_; }
  // Accumulates parameter gradients of dL/dmean and dL/dlog_std (bounded), plus SASA's loss.
  void backward(const ConstMatRef<S>& dmean, const ConstMatRef<S>& dlog_std);

  // The deterministic action tanh(mean) of raw observations (evaluation).
  void actDeterministic(const ConstMatRef<S>& raw_obs, MatRef<S> actions);
  // Actions sampled from the squashed Gaussian of raw observations, noise from rng (collection).
  // Overwrites the caches of forward().
  void actStochastic(const ConstMatRef<S>& raw_obs, Rng& rng, MatRef<S> actions);

  void save(std::ostream& os) const;  // parameters and normalizer
  void load(std::istream& is, const std::string& source_name);

 private:
  void symmetryLossForward();

  sym::SymmetrySpec spec_;
  SacPolicyShape shape_;
  model::AgentMaps maps_;
  int act_dim_;
  nn::ParameterSet<S> params_;
  model::SharedAgentPolicy<S> net_;
  model::RunningMeanStd<S> obs_norm_;
  bool normalize_ = false;
  std::vector<sym::SparseMap> sym_t_, sym_t_transpose_;  // SASA: T'_i and its transpose
  Mat<S> out_, log_std_, dout_, sym_dagent_, sym_residual_, scratch_, eps_, logp_;
  int batch_ = 0;
  S sym_loss_ = S(0);
};

}  // namespace masa::sac
