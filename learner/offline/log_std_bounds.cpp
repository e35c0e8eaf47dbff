#include "learner/offline/log_std_bounds.hpp"

namespace masa::offline {

template <typename S>
void clampLogStd(model::ActorCritic<S>& model, S lo, S hi) {
  const auto& seg = model.params().segment("policy.log_std");
  auto v = model.params().values().segment(seg.offset, seg.size());
  v = v.cwiseMax(lo).cwiseMin(hi);
}

template void clampLogStd<float>(model::ActorCritic<float>&, float, float);
template void clampLogStd<double>(model::ActorCritic<double>&, double, double);

}  // namespace masa::offline
