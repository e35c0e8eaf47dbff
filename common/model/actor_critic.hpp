// The trainable model of one method: normalizer, policy mean, tied log-std, critic, and (for
// SASA) the symmetry losses, with all parameters in one flat ParameterSet so that one Adam,
// one grad-norm clip and one broadcast serve them all.
//
// Training use:   forward(raw_obs) -> mean(), logStd(), value()
//                 backward(dmean, dlog_std, dvalue)   (adds the SASA losses' gradients itself)
// Acting use:     actMean(raw_obs) and logStd().
//
// A model loaded from a squashed policy file (masa_sac's: ModelConfig::squash = kTanh) acts with
// tanh of the mean, SAC's deterministic action: actMean returns tanh(mean). forward() and mean()
// stay the Gaussian's (pre-squash) mean, and such a model cannot be trained (backward throws).
#pragma once

#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "common/model/agent_maps.hpp"
#include "common/model/method.hpp"
#include "common/model/running_mean_std.hpp"
#include "common/model/shared_agent_critic.hpp"
#include "common/model/shared_agent_policy.hpp"
#include "common/model/tied_log_std.hpp"
#include "common/nn/dense_kernels.hpp"
#include "common/nn/parameter_set.hpp"
#include "common/symmetry/symmetry_spec.hpp"

namespace masa::model {

// How the deterministic action leaves the policy network: kNone, the Gaussian's mean itself (PPO);
// kTanh, tanh of it (SAC's squashed Gaussian). Not a config key: a policy file carries it
// (common/policy/policy_file.hpp), and only masa_sac writes kTanh.
enum class ActionSquash { kNone, kTanh };
std::string actionSquashName(ActionSquash s);  // "none" | "tanh"

struct ModelConfig {
  Method method = Method::kMasa;
  std::vector<int> policy_hidden{400, 200, 100};  // Phi
  std::vector<int> critic_hidden{400, 200, 100};  // Psi (last width = features pooled over agents)
  std::vector<int> critic_head_hidden{};          // Theta's hidden widths (empty: linear head)
  nn::Activation activation = nn::Activation::kElu;
  double init_log_std = 0.0;
  double policy_last_layer_scale = 0.01;  // small initial actions
  double sasa_policy_coef = 1.0;          // weight of ||T_i A(o) - A(T_i o)||^2
  double sasa_value_coef = 1.0;           // weight of |V(o) - V(T_i o)|
  bool normalize_obs = true;
  ActionSquash squash = ActionSquash::kNone;  // set from a policy file, never from a config
};

// The log-std classes of a method: MASA ties by the symmetry's orbit classes, MA one std per limb
// slot (each central joint its own), SA and SASA one per action dimension.
std::vector<int> logStdClasses(Method method, const sym::SymmetrySpec& spec);

// MASA must normalize observations equivariantly; SASA too, so that its losses compare A(o) with
// A(T_i o) through the same normalization (T_i commutes with a symmetric normalizer). Others: as is.
template <typename S>
void symmetrizeNormalizer(RunningMeanStd<S>& norm, Method method, const sym::SymmetrySpec& spec);

template <typename S>
class ActorCritic {
 public:
  ActorCritic(const sym::SymmetrySpec& spec, const ModelConfig& config);
  ActorCritic(const ActorCritic&) = delete;
  ActorCritic& operator=(const ActorCritic&) = delete;

  void initialize(Rng& rng);

  const ModelConfig& config() const { return config_; }
  const sym::SymmetrySpec& spec() const { return spec_; }
  // (From the agent maps: the spec recounts its entries on every call, on the robot runner's path.)
  int obsDim() const { return maps_.obs_dim; }
  int actDim() const { return maps_.act_dim; }

  nn::ParameterSet<S>& params() { return params_; }
  const nn::ParameterSet<S>& params() const { return params_; }
  // The flat parameters start with the policy and its log-std, then the critic ("critic*"
  // segments): actors and deployed controllers need only this prefix.
  int policyParamCount() const {
    for (const auto& seg : params_.segments())
      if (seg.name.rfind("critic", 0) == 0) return seg.offset;
    return params_.size();
  }
  RunningMeanStd<S>& obsNormalizer() { return obs_norm_; }
  const RunningMeanStd<S>& obsNormalizer() const { return obs_norm_; }
  RunningMeanStd<S>& valueNormalizer() { return value_norm_; }

  // Training forward on raw observations (obs_dim x B); caches for backward.
  void forward(const ConstMatRef<S>& raw_obs);
  Eigen::Map<const Mat<S>> mean() const;   // act_dim x B
  Eigen::Map<const Mat<S>> value() const;  // 1 x B, in normalized value units
  void logStd(VecRef<S> out) const;
  // SASA losses of the last forward, already weighted (0 for other methods).
  S symmetryPolicyLoss() const { return sym_policy_loss_; }
  S symmetryValueLoss() const { return sym_value_loss_; }

  // Accumulates gradients of the caller's loss (plus the SASA losses for SASA).
  void backward(const ConstMatRef<S>& dmean, const ConstVecRef<S>& dlog_std, const ConstMatRef<S>& dvalue);

  // The deterministic action only (for actors, evaluation, deployment): no critic work. The mean,
  // or tanh(mean) for a squashed policy (config().squash).
  Eigen::Map<const Mat<S>> actMean(const ConstMatRef<S>& raw_obs);
  // V(o) only (1 x B, normalized value units): no policy work. Like actMean, it overwrites the
  // caches of forward(), so backward() must follow a fresh forward() (checked).
  Eigen::Map<const Mat<S>> criticValue(const ConstMatRef<S>& raw_obs);

  // The shared per-agent policy (Phi and the agent maps), e.g. to count its FLOPs.
  const SharedAgentPolicy<S>& policy() const { return policy_; }

  // The fused engine's chunk width of the policy and the critic networks, and what decided it
  // (nn/chunk_tuner.hpp): printed by the learner, so a run records what its CPU chose.
  std::string chunkWidthSummary() const {
    // Without AVX-512 or AVX2 at build time there is no fused engine to tune (a build that reads
    // "not chosen yet" would hide that its kernels are off).
    if (!nn::dense::kAvailable)
      return "none: this build has no AVX-512 or AVX2 kernels, the generic engine runs (GemmWorkspace)";
    return "policy " + policy_.net().chunkTuner().summary() + "; critic " +
           critic_.featureNet().chunkTuner().summary();
  }

  // For a policy that will only act from now on (the robot runner): the parameters can no longer be
  // written (writes throw), and actMean on 1-4 agent columns reads weights packed once for it.
  void freezeForInference() { params_.freeze(); }

  // Parameters and normalizer statistics, for checkpoints.
  void save(std::ostream& os) const;
  void load(std::istream& is, const std::string& source_name);

 private:
  void normalizeInput(const ConstMatRef<S>& raw_obs);
  void computeSymmetryLosses();

  sym::SymmetrySpec spec_;
  ModelConfig config_;
  AgentMaps maps_;
  nn::ParameterSet<S> params_;
  SharedAgentPolicy<S> policy_;
  TiedLogStd<S> log_std_;
  SharedAgentCritic<S> critic_;
  RunningMeanStd<S> obs_norm_;
  RunningMeanStd<S> value_norm_;

  Mat<S> obs_normalized_;
  const S* value_ptr_ = nullptr;  // critic output of the last forward (1 x numPooled*B)
  const S* mean_ptr_ = nullptr;
  int batch_ = 0;
  bool backward_ready_ = false;  // the last call was forward(): its caches are intact
  // SASA scratch: gradients on the orbit copies' actions and values, and residuals.
  std::vector<sym::SparseMap> act_t_transpose_;
  Mat<S> sym_dagent_, sym_residual_, dvalues_;
  S sym_policy_loss_ = S(0), sym_value_loss_ = S(0);
};

}  // namespace masa::model
