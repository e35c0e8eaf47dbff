#include "learner/ppo/rollout_buffer.hpp"

#include <algorithm>

#include "common/core/check.hpp"

namespace masa::ppo {

RolloutBuffer::RolloutBuffer(int num_envs, int horizon, int obs_dim, int act_dim)
    : num_envs_(num_envs), horizon_(horizon), obs_dim_(obs_dim), act_dim_(act_dim) {
  MASA_CHECK(num_envs > 0 && horizon > 0 && obs_dim > 0 && act_dim > 0,
             "rollout buffer needs positive sizes, got envs " << num_envs << ", horizon " << horizon << ", obs "
                                                              << obs_dim << ", act " << act_dim);
  const Eigen::Index n = static_cast<Eigen::Index>(num_envs) * horizon;
  obs_ = Mat<Scalar>::Zero(obs_dim, n);
  actions_ = Mat<Scalar>::Zero(act_dim, n);
  means_ = Mat<Scalar>::Zero(act_dim, n);
  log_probs_ = Mat<Scalar>::Zero(1, n);
  log_stds_ = Mat<Scalar>::Zero(act_dim, n);
  rewards_ = StepMat<Scalar>::Zero(horizon, num_envs);
  terminated_ = FlagMat::Zero(horizon, num_envs);
  truncated_ = FlagMat::Zero(horizon, num_envs);
  bootstrap_obs_ = Mat<Scalar>::Zero(obs_dim, num_envs);
  // Room for one time-out per env and batch; more grows the storage.
  final_entries_.resize(num_envs);
  final_obs_ = Mat<Scalar>::Zero(obs_dim, num_envs);
  values_ = StepMat<Scalar>::Zero(horizon, num_envs);
  advantages_ = StepMat<Scalar>::Zero(horizon, num_envs);
  returns_ = StepMat<Scalar>::Zero(horizon, num_envs);
}

void RolloutBuffer::addFinalObs(int t, int e, const ConstMatRef<Scalar>& obs_column) {
  MASA_CHECK(t >= 0 && t < horizon_ && e >= 0 && e < num_envs_, "final obs at (" << t << ", " << e << ") is outside "
                                                                                  << horizon_ << " x " << num_envs_);
  MASA_CHECK(obs_column.rows() == obs_dim_ && obs_column.cols() == 1,
             "final obs is " << obs_column.rows() << "x" << obs_column.cols() << ", expected " << obs_dim_ << "x1");
  if (num_final_ == final_obs_.cols()) {
    const Eigen::Index cap = std::max<Eigen::Index>(1, 2 * final_obs_.cols());
    final_obs_.conservativeResize(Eigen::NoChange, cap);
    final_entries_.resize(cap);
  }
  final_entries_[num_final_] = {t, e};
  final_obs_.col(num_final_) = obs_column;
  ++num_final_;
}

void RolloutBuffer::checkFinalObs() const {
  FlagMat seen = FlagMat::Zero(horizon_, num_envs_);
  for (int k = 0; k < num_final_; ++k) {
    const auto [t, e] = final_entries_[k];
    MASA_CHECK(truncated_(t, e), "final obs recorded at (" << t << ", " << e << "), which is not truncated");
    MASA_CHECK(!seen(t, e), "two final obs recorded at (" << t << ", " << e << ")");
    seen(t, e) = 1;
  }
  for (int t = 0; t < horizon_; ++t)
    for (int e = 0; e < num_envs_; ++e)
      MASA_CHECK(!truncated_(t, e) || seen(t, e), "truncated step (" << t << ", " << e << ") has no final obs");
}

}  // namespace masa::ppo
