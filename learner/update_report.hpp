// What one update did, and the three places it is told: the lcmt_learner_stats message (lcm-spy,
// dashboards), a row of metrics.csv, and the progress line on stdout.
//
// Counting: one word, "update": one batch collected, then ppo.mini_epochs passes over it in
// minibatches (rl_games calls it an epoch); ppo.max_updates is how many a run makes. Updates are
// numbered from 1, and a policy is named by the update that made it: the policy version the
// learner broadcasts is the number of updates its parameters have seen (0: the initial policy).
#pragma once

#include <cmath>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

#include "common/cluster/communicator.hpp"
#include "common/rollout/rollout.hpp"
#include "learner/algorithm.hpp"
#include "learner/intake/drop_reason.hpp"
#include "masa/lcmt_learner_stats.hpp"

namespace masa::learner {

struct UpdateReport {
  int64_t update = 0;  // this update's number, from 1: the policy version it produced (metrics.csv's first column)
  int64_t env_steps = 0;
  double wall_time_s = 0, fps = 0;
  int num_episodes = 0;
  double mean_return = 0, mean_length = 0, success_rate = -1;
  // The last update in which episodes ended (0: none since the process started), and theirs: what
  // the progress line shows when none ended in this one.
  int64_t last_episodes_update = 0;
  double last_return = std::nan(""), last_length = std::nan("");
  std::vector<double> term_means;
  LearnFigures learned;  // the algorithm's figures of the update (metrics.csv's algorithm columns)
  int64_t dropped_chunks = 0;  // by the assembler, every reason (lost included), since the run began
  int64_t dropped_envs = 0;    // by the collector (stale, overflow), since the run began
  // Where the update's interval went (rank 0's clock): learn_s computing it (PPO's epochs or the
  // off-policy round's gradient steps, collectives included), wait_s waiting for its batch since
  // the previous update ended (evaluation, checkpoint and publishing excluded). A learner that
  // mostly waits wants more actors; one that mostly learns, more ranks (docs/scaling.md).
  double learn_s = std::nan(""), wait_s = std::nan("");
  // The policy mean's evaluation (runner.eval_every): NaN in updates without one.
  double eval_return = std::nan(""), eval_length = std::nan(""), eval_success = std::nan("");
  std::vector<double> eval_progress;  // the task's progress figures (Task::progressNames)
  // The algorithm's part of the progress line (Algorithm::progressFigures).
  std::string algorithm_figures;
};

// Episode statistics of a batch: mean return, length and reward terms, and the success rate over
// the episodes that have a success measure (-1 when none has). NaN means when no episode ended.
// Data-parallel: over every rank's batch (the sums are summed across ranks before dividing).
void summarizeEpisodes(const rollout::Rollout& batch, UpdateReport& report,
                       cluster::Communicator& ranks = cluster::soloCommunicator());

// Names of the reward terms and of the task's progress figures, for the columns.
struct ReportColumns {
  std::vector<std::string> term_names;
  std::vector<std::string> progress_names;
};

// The stats message of an update: chunk drops by reason, then the collector's own drops.
masa::lcmt_learner_stats statsMessage(const UpdateReport& report, const ReportColumns& columns, int64_t run_id,
                                      const DropStats& chunk_drops, int64_t stale_envs, int64_t overflow_envs);

// metrics.csv's columns, and the update's row in them (written to the run's open metrics.csv,
// learner/run_dir/run_files.hpp).
std::vector<std::string> metricsHeader(const ReportColumns& columns);
void writeMetricsRow(std::ostream& out, const UpdateReport& report);

// The progress line (and the evaluation's line when the update had one). `max_updates` <= 0: no
// total and no ETA; `update_interval_s` is the recent wall time per update.
void printProgress(const UpdateReport& report, const ReportColumns& columns, int64_t max_updates,
                   double update_interval_s, int eval_episodes);

}  // namespace masa::learner
