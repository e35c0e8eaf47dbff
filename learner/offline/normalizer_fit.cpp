#include "learner/offline/normalizer_fit.hpp"

#include <algorithm>

namespace masa::offline {

template <typename S>
void fitObservationNormalizer(model::ActorCritic<S>& model, const dataset::TransitionDataset& data) {
  MASA_CHECK(data.obs_dim == model.obsDim(), "dataset observations have " << data.obs_dim << " entries, the model "
                                                                          << model.obsDim());
  constexpr Eigen::Index kChunk = 16384;
  Mat<S> chunk;
  for (Eigen::Index at = 0; at < data.size(); at += kChunk) {
    const Eigen::Index len = std::min<Eigen::Index>(kChunk, data.size() - at);
    chunk = data.obs.middleCols(at, len).template cast<S>();
    model.obsNormalizer().update(chunk);
  }
}

template void fitObservationNormalizer<float>(model::ActorCritic<float>&, const dataset::TransitionDataset&);
template void fitObservationNormalizer<double>(model::ActorCritic<double>&, const dataset::TransitionDataset&);

}  // namespace masa::offline
