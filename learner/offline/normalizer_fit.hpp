// Offline learners know their whole input distribution in advance: the observation normalizer is
// set once from the dataset's observations (counted with their group orbit for MASA, as the
// model's normalizer always does), then held fixed during training.
#pragma once

#include "common/dataset/transition_dataset.hpp"
#include "common/model/actor_critic.hpp"

namespace masa::offline {

// Adds every observation of `data` to the model's normalizer, in chunks (the symmetric update
// needs scratch for N x its batch).
template <typename S>
void fitObservationNormalizer(model::ActorCritic<S>& model, const dataset::TransitionDataset& data);

}  // namespace masa::offline
