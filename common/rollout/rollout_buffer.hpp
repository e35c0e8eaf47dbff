// One batch of trajectories from num_envs environments over `horizon` steps, allocated once.
//
// The samples are a rollout::Rollout (common/rollout/rollout.hpp), the layout every stage from the
// actor on uses; this class adds Eigen views over it and what the update computes from it. Step t
// of env e is column t*E + e of every per-sample matrix (obs, actions, means, log-probs), and entry
// (t, e) of every per-step T x E matrix, which is row-major so that its data has that same order.
// Time-outs (truncated) are kept apart from terminations: a truncated step carries the observation
// the environment reached before it was reset, for the value bootstrap.
#pragma once

#include <cstdint>
#include <vector>

#include "common/core/types.hpp"
#include "common/rollout/rollout.hpp"

namespace masa::rollout {

template <typename S>
using StepMat = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;  // T x E
using FlagMat = StepMat<std::uint8_t>;

// A truncated step (t, e); its pre-reset observation is the same column of finalObs().
struct FinalObsEntry {
  int t = 0;
  int e = 0;
};

class RolloutBuffer {
 public:
  using Scalar = float;
  using SampleMap = Eigen::Map<Mat<Scalar>>;
  using ConstSampleMap = Eigen::Map<const Mat<Scalar>>;
  using StepMap = Eigen::Map<StepMat<Scalar>>;
  using ConstStepMap = Eigen::Map<const StepMat<Scalar>>;
  using FlagMap = Eigen::Map<FlagMat>;
  using ConstFlagMap = Eigen::Map<const FlagMat>;

  RolloutBuffer(int num_envs, int horizon, int obs_dim, int act_dim);

  // A batch short of environments (some were lost on the way): the first num_envs columns of each
  // step. The samples keep their memory (growing back to the constructed size allocates nothing);
  // values, advantages and returns are resized.
  void setNumEnvs(int num_envs);

  int numEnvs() const { return data_.num_envs; }
  int horizon() const { return data_.horizon; }
  int obsDim() const { return data_.obs_dim; }
  int actDim() const { return data_.act_dim; }
  int size() const { return data_.numSteps(); }  // T * E samples
  int column(int t, int e) const { return t * data_.num_envs + e; }

  // The samples, filled in place by the learner's intake (BatchCollector::take) or by a test.
  rollout::Rollout& data() { return data_; }
  const rollout::Rollout& data() const { return data_; }

  // Forgets the time-outs and episodes of the last batch; everything else is overwritten by the next.
  void clear() { data_.clearEvents(); }

  // Views over data().
  SampleMap obs() { return SampleMap(data_.obs.data(), obsDim(), size()); }             // obs_dim x T*E
  SampleMap actions() { return SampleMap(data_.actions.data(), actDim(), size()); }     // act_dim x T*E
  SampleMap means() { return SampleMap(data_.mean.data(), actDim(), size()); }          // behaviour means
  SampleMap logProbs() { return SampleMap(data_.log_prob.data(), 1, size()); }          // 1 x T*E
  // act_dim x E: each environment's behaviour log std (a batch may mix policy versions).
  SampleMap envLogStds() { return SampleMap(data_.env_log_std.data(), actDim(), numEnvs()); }
  StepMap rewards() { return StepMap(data_.reward.data(), horizon(), numEnvs()); }       // T x E
  FlagMap terminated() { return FlagMap(data_.terminated.data(), horizon(), numEnvs()); }  // ended for good
  FlagMap truncated() { return FlagMap(data_.truncated.data(), horizon(), numEnvs()); }    // hit the time limit
  // obs_dim x E, the observation after step T-1 (row T of the rollout's observations).
  SampleMap bootstrapObs() { return SampleMap(data_.obsAt(horizon(), 0), obsDim(), numEnvs()); }
  // Records the pre-reset observation of a time-out at (t, e); in ascending (t, e) order.
  void addFinalObs(int t, int e, const ConstMatRef<Scalar>& obs_column);

  ConstSampleMap obs() const { return ConstSampleMap(data_.obs.data(), obsDim(), size()); }
  ConstSampleMap actions() const { return ConstSampleMap(data_.actions.data(), actDim(), size()); }
  ConstSampleMap means() const { return ConstSampleMap(data_.mean.data(), actDim(), size()); }
  ConstSampleMap logProbs() const { return ConstSampleMap(data_.log_prob.data(), 1, size()); }
  ConstSampleMap envLogStds() const { return ConstSampleMap(data_.env_log_std.data(), actDim(), numEnvs()); }
  ConstStepMap rewards() const { return ConstStepMap(data_.reward.data(), horizon(), numEnvs()); }
  ConstFlagMap terminated() const { return ConstFlagMap(data_.terminated.data(), horizon(), numEnvs()); }
  ConstFlagMap truncated() const { return ConstFlagMap(data_.truncated.data(), horizon(), numEnvs()); }
  ConstSampleMap bootstrapObs() const { return ConstSampleMap(data_.obsAt(horizon(), 0), obsDim(), numEnvs()); }
  int numFinalObs() const { return data_.numFinal(); }
  FinalObsEntry finalObsEntry(int k) const {
    const int idx = data_.final_index[k];
    return {idx / numEnvs(), idx % numEnvs()};
  }
  ConstSampleMap finalObs() const { return ConstSampleMap(data_.final_obs.data(), obsDim(), numFinalObs()); }

  // Throws unless every truncated step has exactly one final observation and vice versa.
  void checkFinalObs() const;

  // Computed by the learner, in real (denormalized) value units.
  StepMat<Scalar>& values() { return values_; }
  StepMat<Scalar>& advantages() { return advantages_; }
  StepMat<Scalar>& returns() { return returns_; }
  const StepMat<Scalar>& values() const { return values_; }
  const StepMat<Scalar>& advantages() const { return advantages_; }
  const StepMat<Scalar>& returns() const { return returns_; }

 private:
  rollout::Rollout data_;
  StepMat<Scalar> values_, advantages_, returns_;
};

}  // namespace masa::rollout
