// IQL's twin Q networks Q1, Q2 on state-action pairs, both in one ParameterSet (one Adam), each a
// SharedAgentCritic over the pair maps of state_action_maps.hpp: symmetric for MASA, plain MLPs on
// [o; a] for SA. A second TwinQ of the same shape serves as the Polyak-averaged target.
#pragma once

#include "common/model/shared_agent_critic.hpp"
#include "common/nn/parameter_set.hpp"

namespace masa::offline {

template <typename S>
class TwinQ {
 public:
  // hidden: each Q's widths (the last one is the feature width pooled over agents).
  TwinQ(const sym::SymmetrySpec& spec, model::Method method, const std::vector<int>& hidden,
        nn::Activation activation);
  // The same on maps of state-action pairs given by the caller (pair_maps.obs_dim = obs + act):
  // how the off-policy learner (learner/sac) serves the methods this library does not (SASA, MA).
  TwinQ(const sym::SymmetrySpec& spec, model::AgentMaps pair_maps, const std::vector<int>& hidden,
        nn::Activation activation);
  TwinQ(const TwinQ&) = delete;
  TwinQ& operator=(const TwinQ&) = delete;

  void initialize(Rng& rng);
  nn::ParameterSet<S>& params() { return params_; }
  const nn::ParameterSet<S>& params() const { return params_; }

  // Q1 and Q2 (2 x B, row k = Q_(k+1)) of normalized observations (obs_dim x B) and actions
  // (act_dim x B); caches for backward. The view is valid until the next forward.
  Eigen::Block<Mat<S>> forward(const ConstMatRef<S>& obs, const ConstMatRef<S>& actions);
  // Accumulates parameter gradients of dL/dQ (2 x B) of the last forward. If dactions is given it
  // receives dL/da (act_dim x B), what an actor trained through Q (SAC) needs.
  void backward(const ConstMatRef<S>& dq, MatRef<S>* dactions = nullptr);
  // dactions = dL/da (act_dim x B) of dL/dQ (2 x B) of the last forward, the parameters'
  // gradients left as they are: an actor trained through Q (SAC) needs no Q gradients, and their
  // products are a third of a backward.
  void actionGradient(const ConstMatRef<S>& dq, MatRef<S> dactions);

  // Q1 alone (1 x B), for an actor trained through Q1 only (TD3): half of forward(). Its view is
  // valid until the next forward; q1ActionGradient then gives dL/da of dL/dQ1 (1 x B), the
  // parameters' gradients left as they are.
  Eigen::Block<Mat<S>> q1Forward(const ConstMatRef<S>& obs, const ConstMatRef<S>& actions);
  void q1ActionGradient(const ConstMatRef<S>& dq1, MatRef<S> dactions);
  // min(Q1, Q2) into out (1 x B): IQL's pessimistic target.
  void minQ(const ConstMatRef<S>& obs, const ConstMatRef<S>& actions, MatRef<S> out);

  // target <- (1 - rate) target + rate * online, parameter by parameter (rate 1: a copy).
  void moveTowards(const TwinQ& online, S rate);

 private:
  // [obs; actions] into pair_ (checked), its first b columns.
  MatRef<S> pairOf(const ConstMatRef<S>& obs, const ConstMatRef<S>& actions);

  model::AgentMaps maps_;
  int obs_dim_, act_dim_;
  nn::ParameterSet<S> params_;
  model::SharedAgentCritic<S> q1_, q2_;
  Mat<S> pair_, q_, dpair1_, dpair2_;
};

}  // namespace masa::offline
