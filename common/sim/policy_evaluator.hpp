// Runs a policy in its task for whole episodes and measures it: return, length, reward terms,
// success where the task has one, and the task's own progress figures (Task::progress). Episode k
// resets from its own seed (base seed + k), so any episode can be replayed alone; all episodes
// step together as one batch (one network call per step), and environments step in parallel.
// The result depends on the seeds only, not on the thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "common/model/actor_critic.hpp"
#include "common/sim/registry.hpp"

namespace masa::task {

struct EvalOptions {
  int episodes = 20;
  uint64_t seed = 0;         // episode k resets from seed + k
  bool deterministic = true;  // act with the policy mean; false: sample from the policy
  int max_steps = 0;          // cut episodes here (0: the task's limit)
  int threads = 1;
};

struct EpisodeResult {
  uint64_t seed = 0;
  double ret = 0;
  int length = 0;
  bool terminated = false, truncated = false;
  int success = -1;  // -1: the task has no success notion
  std::vector<double> terms, progress;
  std::vector<double> physics;  // env.randomization's draws (Task::physicsDrawNames())
};

struct Moments {
  double mean = 0, std = 0, min = 0, max = 0;
};

struct EvalSummary {
  std::vector<std::string> term_names, progress_names, physics_names;
  std::vector<EpisodeResult> episodes;
  Moments ret, length;
  std::vector<Moments> terms, progress, physics;
  double success_rate = -1;  // -1: the task has no success notion
  int time_limit_reached = 0;  // episodes that ran to the time limit (or max_steps)
};

class PolicyEvaluator {
 public:
  // Called after every step t of episode k (for video), the task in its post-step state; `last`
  // on the episode's final step.
  using StepHook = std::function<void(int k, int t, const Task& task, bool last)>;
  // Called after every step t of episode k with what a dataset records: the observation the
  // action was chosen from, the action taken, and the step's outcome; the task is in its
  // post-step state (its observe() gives the next observation). Called in episode order.
  struct Transition {
    int k = 0, t = 0;
    const float* obs = nullptr;
    const float* action = nullptr;
    StepOutcome outcome;
    bool last = false;
  };
  using TransitionHook = std::function<void(const Transition& tr, const Task& task)>;

  PolicyEvaluator(const TaskFactory& factory, model::ActorCritic<float>& model);
  EvalSummary run(const EvalOptions& options, const StepHook& hook = {}, const TransitionHook& transitions = {});

 private:
  const TaskFactory* factory_;
  model::ActorCritic<float>* model_;
};

// A fixed-width table of a summary, for terminals and README files.
std::string formatSummary(const EvalSummary& s);

}  // namespace masa::task
