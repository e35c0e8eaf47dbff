// The policy half of a method's ActorCritic, for processes that only act: the actors and the robot
// runner. The observation normalizer, the shared per-agent policy Phi and the tied log-std, with
// the parameters laid out exactly as the ActorCritic's policy prefix (its policyParamCount()
// values, same segments, same offsets), so that the learner's broadcast and a policy file's
// parameters load as they are. No critic, no gradients, no training caches.
#pragma once

#include <memory>

#include "common/model/actor_critic.hpp"

namespace masa::model {

template <typename S>
class InferencePolicy {
 public:
  InferencePolicy(const sym::SymmetrySpec& spec, const ModelConfig& config);
  InferencePolicy(const InferencePolicy&) = delete;
  InferencePolicy& operator=(const InferencePolicy&) = delete;

  // The acting part of a model: its parameters' policy prefix and its observation normalizer.
  static std::unique_ptr<InferencePolicy> of(const ActorCritic<S>& model);

  // The policy's draws of ActorCritic::initialize: the same parameters as a model's prefix for the
  // same generator state (the critic's draws, which follow, are not taken).
  void initialize(Rng& rng);
  const ModelConfig& config() const { return config_; }
  int obsDim() const { return maps_.obs_dim; }
  int actDim() const { return maps_.act_dim; }
  nn::ParameterSet<S>& params() { return params_; }  // size: the ActorCritic's policyParamCount()
  const nn::ParameterSet<S>& params() const { return params_; }
  RunningMeanStd<S>& obsNormalizer() { return obs_norm_; }
  const RunningMeanStd<S>& obsNormalizer() const { return obs_norm_; }

  // The deterministic action of raw observations (obs_dim x B): the mean, or tanh(mean) for a
  // squashed policy (config().squash). The view is valid until the next call.
  Eigen::Map<const Mat<S>> actMean(const ConstMatRef<S>& raw_obs);
  void logStd(VecRef<S> out) const { log_std_.get(out); }
  // The parameters can no longer be written, and actMean on 1-4 agent columns reads weights packed
  // once for it (ActorCritic::freezeForInference).
  void freezeForInference() { params_.freeze(); }

 private:
  sym::SymmetrySpec spec_;
  ModelConfig config_;
  AgentMaps maps_;
  nn::ParameterSet<S> params_;
  SharedAgentPolicy<S> policy_;
  TiedLogStd<S> log_std_;
  RunningMeanStd<S> obs_norm_;
  Mat<S> obs_normalized_;
};

}  // namespace masa::model
