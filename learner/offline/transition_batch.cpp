#include "learner/offline/transition_batch.hpp"

#include "common/core/check.hpp"

namespace masa::offline {

template <typename S>
void TransitionBatch<S>::resize(int obs_dim, int act_dim, int batch) {
  if (obs.rows() != obs_dim || obs.cols() != batch) {
    obs.resize(obs_dim, batch);
    next_obs.resize(obs_dim, batch);
  }
  if (actions.rows() != act_dim || actions.cols() != batch) actions.resize(act_dim, batch);
  if (rewards.cols() != batch) {
    rewards.resize(1, batch);
    not_terminal.resize(1, batch);
  }
}

template <typename S>
void sampleBatch(const dataset::TransitionDataset& data, int batch_size, Rng& rng, TransitionBatch<S>& batch) {
  MASA_CHECK(data.size() > 0, "cannot sample from an empty dataset");
  MASA_CHECK(batch_size > 0, "batch size must be positive, got " << batch_size);
  batch.resize(data.obs_dim, data.act_dim, batch_size);
  std::uniform_int_distribution<int64_t> pick(0, data.size() - 1);
  for (int b = 0; b < batch_size; ++b) {
    const int64_t k = pick(rng);
    batch.obs.col(b) = data.obs.col(k).template cast<S>();
    batch.next_obs.col(b) = data.next_obs.col(k).template cast<S>();
    batch.actions.col(b) = data.actions.col(k).template cast<S>();
    batch.rewards(0, b) = static_cast<S>(data.rewards(k));
    batch.not_terminal(0, b) = data.terminals[k] ? S(0) : S(1);
  }
}

template struct TransitionBatch<float>;
template struct TransitionBatch<double>;
template void sampleBatch<float>(const dataset::TransitionDataset&, int, Rng&, TransitionBatch<float>&);
template void sampleBatch<double>(const dataset::TransitionDataset&, int, Rng&, TransitionBatch<double>&);

}  // namespace masa::offline
