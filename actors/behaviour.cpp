#include "actors/behaviour.hpp"

#include "actors/gaussian_behaviour.hpp"
#include "actors/squashed_behaviour.hpp"

namespace masa::actor {

std::unique_ptr<Behaviour> makeBehaviour(const config::RunConfig& rc, const sym::SymmetrySpec& spec) {
  if (rc.learner == "off_policy") return std::make_unique<SquashedBehaviour>(rc, spec);
  return std::make_unique<GaussianBehaviour>(rc, spec);
}

}  // namespace masa::actor
