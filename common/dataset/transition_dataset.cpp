#include "common/dataset/transition_dataset.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace masa::dataset {

void TransitionDataset::validate() const {
  auto fail = [&](const std::string& what) {
    throw std::runtime_error("dataset" + (task.empty() ? std::string() : " of " + task) + ": " + what);
  };
  const int64_t n = size();
  if (obs_dim <= 0 || act_dim <= 0) fail("empty observation or action dimension");
  if (obs.rows() != obs_dim || next_obs.rows() != obs_dim || actions.rows() != act_dim)
    fail("matrix rows differ from obs_dim / act_dim");
  if (obs.cols() != n || next_obs.cols() != n || actions.cols() != n ||
      static_cast<int64_t>(terminals.size()) != n || static_cast<int64_t>(timeouts.size()) != n)
    fail("the columns of obs, next_obs, actions, terminals and timeouts differ from the rewards' count");
  if (!obs.allFinite() || !next_obs.allFinite() || !actions.allFinite() || !rewards.allFinite())
    fail("non-finite numbers in the transitions");
  int64_t next = 0;
  for (const EpisodeInfo& e : episodes) {
    if (e.start != next || e.length <= 0) {
      std::ostringstream os;
      os << "episode " << e.episode_id << " starts at " << e.start << " with length " << e.length
         << "; expected a positive length from column " << next;
      fail(os.str());
    }
    if (e.policy_id < 0 || e.policy_id >= static_cast<int32_t>(policy_names.size()))
      fail("episode " + std::to_string(e.episode_id) + " names policy " + std::to_string(e.policy_id) +
           " of " + std::to_string(policy_names.size()));
    next += e.length;
  }
  if (next != n) fail("the episodes cover " + std::to_string(next) + " of " + std::to_string(n) + " transitions");
}

}  // namespace masa::dataset
