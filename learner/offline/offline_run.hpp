// One offline training run, from a dataset in memory to a run directory a user reads like a PPO
// run's:
//   config.yaml          the resolved configuration (its offline section says algo and augment)
//   metrics.csv          every offline.log_every steps: step, wall_s, steps_per_s, the algorithm's
//                        losses and figures (averaged over those steps), and where an evaluation
//                        ran: eval_return, eval_length, eval_success, eval_<task progress>
//   learning_curve.png   drawn from it (gnuplot; learning_curve.gp redraws it)
//   policy.bin           the policy (and V for IQL) as masa_eval and the robot runner load it,
//                        written with every evaluation
//   eval.txt             the final evaluation (offline.final_eval_episodes episodes, policy mean)
// The dataset is checked against the run first: its task, its dimensions against the spec's, not
// empty, consistent (TransitionDataset::validate).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "common/config/run_config.hpp"
#include "common/dataset/transition_dataset.hpp"
#include "common/sim/policy_evaluator.hpp"
#include "learner/offline/offline_config.hpp"

namespace masa::offline {

struct OfflineRunOptions {
  std::string run_dir;
  bool verbose = true;   // a progress line every offline.log_every steps
  int eval_threads = 1;  // threads stepping evaluation episodes
};

// Throws std::runtime_error naming what does not fit: another task, other dimensions, no data.
void checkDatasetFitsRun(const dataset::TransitionDataset& data, const config::RunConfig& rc,
                         const sym::SymmetrySpec& spec);

class OfflineRun {
 public:
  OfflineRun(const config::RunConfig& rc, dataset::TransitionDataset data, OfflineRunOptions options);
  ~OfflineRun();

  // Trains offline.steps gradient steps with periodic evaluations, then the final one; returns it
  // (no episodes when offline.final_eval_episodes is 0).
  task::EvalSummary run();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace masa::offline
