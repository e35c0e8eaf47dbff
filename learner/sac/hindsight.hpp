// Hindsight experience replay (Andrychowicz et al. 2017, the "future" strategy) on the off-policy
// learner's replay: a share of each batch (sac.her_share) gets as its goal what its episode
// achieved at a step stored at or after the transition's (within sac.her_future_window steps), and
// the rewards and terminations the task gives for that goal (common/sim/goal_relabeling.hpp).
//
// MASA stays exact: the constructor refuses a task whose goal entries the spec transforms
// otherwise than its achieved entries, so that relabeling commutes with every T_i and a relabeled
// observation is as symmetric as a real one (the policy stays equivariant, the twin Q invariant).
// With a share of 0 sampling is the replay's own, draw for draw.
#pragma once

#include <memory>

#include "common/config/run_config.hpp"
#include "common/config/sac_config.hpp"
#include "common/sim/goal_relabeling.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "learner/sac/replay_buffer.hpp"

namespace masa::sac {

class Hindsight {
 public:
  // relabeling: the task's (null when it declares no goal). Throws masa::ConfigError naming
  // sac.her_share when relabeling is asked of a task without a goal, and std::invalid_argument
  // when the spec does not act on the goal as on what is achieved.
  Hindsight(const config::RunConfig& rc, const SacConfig& sc, std::unique_ptr<task::GoalRelabeling> relabeling,
            const sym::SymmetrySpec& spec);

  bool enabled() const { return share_ > 0.0; }
  const task::GoalRelabeling* relabeling() const { return relabeling_.get(); }

  // batch_size transitions as ReplayBuffer::sample draws them; each is relabeled with probability
  // share, its future step drawn right after its slot. Returns how many were relabeled.
  template <typename S>
  int sample(const ReplayBuffer& replay, int batch_size, int n_step, double discount, Rng& rng,
              ReplayBatch<S>& batch) const;

 private:
  double share_;
  long long window_;
  std::unique_ptr<task::GoalRelabeling> relabeling_;
};

// Throws std::invalid_argument unless every T_i of the spec maps the goal entries onto the goal
// entries with the same coefficients as the achieved entries onto the achieved ones.
void checkGoalSymmetry(const task::GoalRelabeling& relabeling, const sym::SymmetrySpec& spec);

}  // namespace masa::sac
