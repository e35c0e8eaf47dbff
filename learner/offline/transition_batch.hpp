// A minibatch of transitions drawn uniformly, with replacement, from a dataset (as BC and IQL
// sample: every gradient step an independent batch).
#pragma once

#include "common/core/types.hpp"
#include "common/dataset/transition_dataset.hpp"

namespace masa::offline {

template <typename S>
struct TransitionBatch {
  Mat<S> obs, next_obs;  // obs_dim x B, raw (the model normalizes)
  Mat<S> actions;        // act_dim x B
  Mat<S> rewards;        // 1 x B
  Mat<S> not_terminal;   // 1 x B: 0 where the episode terminated (no bootstrap), else 1 (time-outs bootstrap)

  int size() const { return static_cast<int>(rewards.cols()); }
  void resize(int obs_dim, int act_dim, int batch);
};

// Fills `batch` with `batch_size` transitions at indices drawn from `rng` (one draw per sample, in
// order). Allocates only when the sizes change.
template <typename S>
void sampleBatch(const dataset::TransitionDataset& data, int batch_size, Rng& rng, TransitionBatch<S>& batch);

}  // namespace masa::offline
