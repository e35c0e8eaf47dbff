#include "common/rollout/rollout_buffer.hpp"

#include "common/core/check.hpp"

namespace masa::rollout {

RolloutBuffer::RolloutBuffer(int num_envs, int horizon, int obs_dim, int act_dim) {
  MASA_CHECK(num_envs > 0 && horizon > 0 && obs_dim > 0 && act_dim > 0,
             "rollout buffer needs positive sizes, got envs " << num_envs << ", horizon " << horizon << ", obs "
                                                              << obs_dim << ", act " << act_dim);
  data_.allocate(num_envs, horizon, obs_dim, act_dim);
  values_ = StepMat<Scalar>::Zero(horizon, num_envs);
  advantages_ = StepMat<Scalar>::Zero(horizon, num_envs);
  returns_ = StepMat<Scalar>::Zero(horizon, num_envs);
}

void RolloutBuffer::setNumEnvs(int num_envs) {
  MASA_CHECK(num_envs > 0, "rollout buffer needs a positive number of environments, got " << num_envs);
  data_.allocate(num_envs, horizon(), obsDim(), actDim(), data_.term_names);
  if (values_.cols() != num_envs) {
    values_.resize(horizon(), num_envs);
    advantages_.resize(horizon(), num_envs);
    returns_.resize(horizon(), num_envs);
  }
}

void RolloutBuffer::addFinalObs(int t, int e, const ConstMatRef<Scalar>& obs_column) {
  MASA_CHECK(obs_column.rows() == obsDim() && obs_column.cols() == 1,
             "final obs is " << obs_column.rows() << "x" << obs_column.cols() << ", expected " << obsDim() << "x1");
  const Vec<Scalar> column = obs_column;  // contiguous, whatever the caller's stride
  data_.addFinal(t, e, column.data());
}

void RolloutBuffer::checkFinalObs() const {
  const int E = numEnvs();
  MASA_CHECK(data_.final_obs.size() == data_.final_index.size() * static_cast<std::size_t>(obsDim()),
             "final_obs holds " << data_.final_obs.size() << " floats for " << data_.final_index.size() << " truncations");
  int previous = -1;
  for (int k = 0; k < numFinalObs(); ++k) {
    const int idx = data_.final_index[k];
    MASA_CHECK(idx >= 0 && idx < size(), "final obs at step index " << idx << " is outside " << horizon() << " x " << E);
    MASA_CHECK(idx > previous, "final obs at (" << idx / E << ", " << idx % E << ") repeated or out of order");
    MASA_CHECK(data_.truncated[idx], "final obs recorded at (" << idx / E << ", " << idx % E << "), which is not truncated");
    previous = idx;
  }
  int truncations = 0;
  for (uint8_t f : data_.truncated) truncations += f != 0;
  MASA_CHECK(truncations == numFinalObs(),
             truncations << " truncated steps but " << numFinalObs() << " final observations: a truncated step has none");
}

}  // namespace masa::rollout
