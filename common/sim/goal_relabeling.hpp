// What a goal-conditioned task tells the off-policy learner so that it can relabel stored
// transitions with goals achieved later (hindsight experience replay, learner/sac/hindsight.hpp).
//
// The observation holds the goal the policy is asked to reach (goalEntries) and, in the next
// observation of a step, what the step achieved (achievedEntries, the same number of entries with
// the same meaning: TriFinger's cube pose against its goal pose). Relabeling writes an achieved
// value into the goal entries of a transition's observations and asks the task for the reward,
// termination and success the step would have had with that goal, from what the transition
// stores. For MASA the symmetry must act on the goal entries exactly as on the achieved ones
// (hindsight.cpp checks it against the spec), so a relabeled observation is one the group knows.
#pragma once

#include <vector>

namespace masa::task {

struct RelabeledStep {
  double reward = 0.0;
  bool terminated = false;
  bool success = false;
};

class GoalRelabeling {
 public:
  virtual ~GoalRelabeling() = default;
  // Observation entries of the desired goal, and of what was achieved (pairwise, same length).
  virtual const std::vector<int>& goalEntries() const = 0;
  virtual const std::vector<int>& achievedEntries() const = 0;
  // The step obs -> next_obs, stored with `reward` and `terminated` for the goal in obs, as it
  // would have been for `goal` (goalEntries().size() values, in the goal entries' order).
  virtual RelabeledStep relabel(const float* obs, const float* next_obs, double reward, bool terminated,
                                const float* goal) const = 0;
};

}  // namespace masa::task
