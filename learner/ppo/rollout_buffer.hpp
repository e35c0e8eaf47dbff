// One batch of trajectories from num_envs environments over `horizon` steps, allocated once.
//
// Step t of env e is column t*E + e of every per-sample matrix (obs, actions, means, log-probs),
// and entry (t, e) of every per-step T x E matrix, which is row-major so that its data has that
// same order. Time-outs (truncated) are kept apart from terminations: a truncated step carries the
// observation the environment reached before it was reset, for the value bootstrap.
#pragma once

#include <cstdint>
#include <vector>

#include "common/core/types.hpp"

namespace masa::ppo {

template <typename S>
using StepMat = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;  // T x E
using FlagMat = StepMat<std::uint8_t>;

// A truncated step (t, e) and the column of its pre-reset observation in finalObs().
struct FinalObsEntry {
  int t = 0;
  int e = 0;
};

class RolloutBuffer {
 public:
  using Scalar = float;

  RolloutBuffer(int num_envs, int horizon, int obs_dim, int act_dim);

  int numEnvs() const { return num_envs_; }
  int horizon() const { return horizon_; }
  int obsDim() const { return obs_dim_; }
  int actDim() const { return act_dim_; }
  int size() const { return num_envs_ * horizon_; }  // T * E samples
  int column(int t, int e) const { return t * num_envs_ + e; }

  // Forgets the time-outs of the last batch; everything else is overwritten by the next one.
  void clear() { num_final_ = 0; }

  // Filled by the collector.
  Mat<Scalar>& obs() { return obs_; }                    // obs_dim x T*E
  Mat<Scalar>& actions() { return actions_; }            // act_dim x T*E
  Mat<Scalar>& means() { return means_; }                // act_dim x T*E, behaviour policy means
  Mat<Scalar>& logProbs() { return log_probs_; }         // 1 x T*E, behaviour log-probs
  // act_dim x T*E, behaviour log-std of each sample: with max_policy_lag > 0 one batch mixes
  // rollouts of several policy versions, each with its own state-independent std.
  Mat<Scalar>& logStds() { return log_stds_; }
  StepMat<Scalar>& rewards() { return rewards_; }        // T x E
  FlagMat& terminated() { return terminated_; }          // T x E, 1 where the episode ended for good
  FlagMat& truncated() { return truncated_; }            // T x E, 1 where it hit the time limit
  Mat<Scalar>& bootstrapObs() { return bootstrap_obs_; }  // obs_dim x E, observation after step T-1
  // Records the pre-reset observation of a time-out at (t, e) (grows storage only when needed).
  void addFinalObs(int t, int e, const ConstMatRef<Scalar>& obs_column);

  const Mat<Scalar>& obs() const { return obs_; }
  const Mat<Scalar>& actions() const { return actions_; }
  const Mat<Scalar>& means() const { return means_; }
  const Mat<Scalar>& logProbs() const { return log_probs_; }
  const Mat<Scalar>& logStds() const { return log_stds_; }
  const StepMat<Scalar>& rewards() const { return rewards_; }
  const FlagMat& terminated() const { return terminated_; }
  const FlagMat& truncated() const { return truncated_; }
  const Mat<Scalar>& bootstrapObs() const { return bootstrap_obs_; }
  int numFinalObs() const { return num_final_; }
  const FinalObsEntry& finalObsEntry(int k) const { return final_entries_[k]; }
  auto finalObs() const { return final_obs_.leftCols(num_final_); }  // obs_dim x numFinalObs()

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
  int num_envs_, horizon_, obs_dim_, act_dim_;
  Mat<Scalar> obs_, actions_, means_, log_probs_, log_stds_;
  StepMat<Scalar> rewards_;
  FlagMat terminated_, truncated_;
  Mat<Scalar> bootstrap_obs_;
  std::vector<FinalObsEntry> final_entries_;
  Mat<Scalar> final_obs_;  // obs_dim x capacity; the first num_final_ columns are in use
  int num_final_ = 0;
  StepMat<Scalar> values_, advantages_, returns_;
};

}  // namespace masa::ppo
