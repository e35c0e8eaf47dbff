#include "learner/algorithms/algorithm_catalog.hpp"

#include <stdexcept>

#include "learner/ppo_algorithm.hpp"
#include "learner/sac/off_policy_rule.hpp"

namespace masa::learner {

std::unique_ptr<Algorithm> makeAlgorithm(const config::RunConfig& rc, Rng& rng, cluster::Communicator& ranks) {
  if (rc.learner == "ppo") return std::make_unique<PpoAlgorithm>(rc, rng, ranks);
  if (rc.learner == "off_policy") return std::make_unique<sac::OffPolicyRule>(rc, rng);
  throw std::runtime_error("learner: '" + rc.learner + "' is none of ppo, off_policy");
}

}  // namespace masa::learner
