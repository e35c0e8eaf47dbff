// The learner process: receives rollout chunks over LCM, gathers them into batches, has its
// algorithm (learner/algorithm.hpp: PPO, or SAC/TD3 on a replay) learn from each, and broadcasts
// the new parameters.
//
// Chunks take the raw path (RolloutAssembler::acceptEncoded) because lcm-gen's decoder trusts
// hostile length fields. Nothing waits for a particular actor or chunk: the collector hands out a
// batch as soon as enough environments from whoever is alive have arrived, and the parameters are
// re-published periodically so that a lost broadcast never stalls the actors.
//
// Run directory: config.yaml (resolved config), metrics.csv (one row per update, with an evaluation
// of the policy mean every runner.eval_every updates), checkpoint.bin (learner state, to resume),
// the algorithm's own files (its round table, its streamed state) and policy.bin (what inference
// needs: masa_eval, deployment), each written atomically (tmp + rename).
#pragma once

#include <atomic>
#include <cmath>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/cluster/communicator.hpp"
#include "common/config/run_config.hpp"
#include "common/sim/registry.hpp"
#include "common/transport/message_bus.hpp"
#include "common/transport/transport.hpp"
#include "learner/intake/batch_collector.hpp"
#include "learner/intake/rollout_assembler.hpp"
#include "learner/intake/round_tracker.hpp"
#include "learner/run_dir/csv_events.hpp"
#include "learner/run_dir/event_file.hpp"
#include "learner/run_dir/run_files.hpp"
#include "learner/run_dir/learning_curve.hpp"
#include "learner/params_delivery.hpp"
#include "learner/update_report.hpp"
#include "learner/algorithm.hpp"
#include "common/rollout/rollout_buffer.hpp"
#include "learner/silence_watch.hpp"
#include "masa/lcmt_actor_heartbeat.hpp"

namespace masa::learner {

struct LearnerOptions {
  std::string url;            // LCM provider URL ("" = LCM's default)
  std::string run_dir;        // created if missing
  int64_t run_id = 0;         // 0: random from the clock, or the checkpoint's when resuming
  bool resume = false;        // load <run_dir>/checkpoint.bin and append to metrics.csv
  // Authenticates every message (common/transport/message_auth.hpp); none: unsigned (--no-auth,
  // or in-process memq runs).
  std::optional<transport::RunKey> run_key;
  // A signed run instead (common/transport/message_sign.hpp): the learner's own key and the run's
  // roster; run_key is then unused.
  std::optional<transport::SignedMode> signed_mode;
  bool verbose = true;  // one progress line per update on stdout
  // Data-parallel (docs/scaling.md): this process is learner rank ranks->rank() of ranks->size(),
  // taking rollout.num_envs / size environments of every batch from the actors that send to its
  // rollout_url. Rank 0 alone publishes parameters and stats (on url) and writes the run
  // directory; every rank checks every rank_check_every updates that all hold the same parameters.
  // Null: the only learner.
  cluster::Communicator* ranks = nullptr;
  std::string rollout_url;  // "" = url
  int rank_check_every = 10;
  // Makes the run's algorithm from the run config, the learner's seeded generator and the ranks:
  // masa_learner and masa_train pass learner/algorithms' catalog (every `learner` value), a test
  // or benchmark of PPO alone makePpoAlgorithm. Required: the learner knows no algorithm by name.
  std::function<std::unique_ptr<Algorithm>(const config::RunConfig&, Rng&, cluster::Communicator&)> make_algorithm;
  // In-process (masa_train): every channel on this bus (a transport::LocalBus: typed messages
  // handed over without encoding), owned by the caller; url, rollout_url and the keys are unused.
  // Null: the learner makes its LCM transports from url and rollout_url.
  transport::MessageBus* bus = nullptr;
};

class Learner {
 public:
  Learner(const config::RunConfig& rc, const LearnerOptions& options);
  ~Learner();
  Learner(const Learner&) = delete;
  Learner& operator=(const Learner&) = delete;

  // One turn of the loop: waits up to timeout_ms for LCM traffic, handles everything queued, runs
  // one update if a full batch is there, and re-publishes the parameters when due. Returns true
  // when an update ran.
  bool step(int timeout_ms);
  // step() until `max_updates` updates have run in total (counting resumed ones) or *stop is set;
  // then checkpoints and renders the learning curve.
  void run(int64_t max_updates, const std::atomic<bool>* stop);

  void writeCheckpoint();
  // Called after each checkpoint is written, with its update count: masa_train saves its actor's
  // environments then, so that a resume goes on exactly (tools/train.cpp).
  void setCheckpointHook(std::function<void(int64_t updates)> hook) { checkpoint_hook_ = std::move(hook); }
  void writeSnapshot();
  void publishParams();
  // The total number of updates planned, for the progress line's ETA (run() sets it too).
  void setMaxUpdates(int64_t max_updates) { max_updates_ = max_updates; }
  // Renders <run dir>/learning_curve.png now (false without gnuplot or before the first update).
  bool renderLearningCurve();

  // The intake's transport (rollouts); rank 0's parameters and stats go out on publisher().
  transport::MessageBus& transport() { return *transport_; }
  transport::MessageBus& publisher() { return policy_transport_ ? *policy_transport_ : *transport_; }
  bool isLeadRank() const { return ranks_->rank() == 0; }
  int64_t runId() const { return run_id_; }
  // Updates done (resumed ones included). The policy version is the same count: the number of
  // updates the broadcast parameters have seen (update_report.hpp says how updates are counted).
  int64_t updates() const { return updates_; }
  int64_t version() const { return updates_; }
  int64_t envSteps() const { return env_steps_; }
  const std::string& runDir() const { return dir_; }
  Algorithm& algorithm() { return *algorithm_; }
  // The assembler's counts, and the chunks the transport dropped for want of a valid tag.
  DropStats dropStats() const;
  // One unit each: rollout chunks the assembler dropped (or counted lost), and environments the
  // collector dropped (stale or overflowing its pool).
  int64_t droppedChunks() const;
  int64_t droppedEnvs() const;
  // Updates that ran on a batch short of lost environments (runner.min_batch_fraction).
  int64_t shortBatches() const { return collector_ ? collector_->stats().short_batches : 0; }
  // Data-parallel ranks: how many ranks heard no rollout data for runner.rank_silence_stop_s and so
  // stopped the run (0: it was not stopped that way).
  int silentRanksAtStop() const { return silent_ranks_at_stop_; }
  // Parameter broadcasts repeated because a live actor had not acknowledged them (params_delivery.hpp).
  int64_t unacknowledgedRepeats() const { return unacknowledged_repeats_; }
  int acknowledgingActors() const { return delivery_.knownActors(); }
  const UpdateReport& lastReport() const { return report_; }

 private:
  std::unique_ptr<transport::Transport> makeTransport(const std::string& url) const;
  // A chunk the assembler has judged (from bytes, or a message handed over in-process).
  void onChunk(const Verdict& v);
  void onHeartbeat(const masa::lcmt_actor_heartbeat& m);
  // How long step() may wait for traffic: at most timeout_ms, less when a short batch or a repeat
  // of the parameters comes due sooner.
  int waitMs(int timeout_ms) const;
  void update();
  // The algorithm's streamed state beside checkpoint.bin (Algorithm::sideState, sealed; written
  // under a "next" name until checkpoint.bin is).
  std::string sideStatePath(bool next) const;
  void writeSideState(const std::string& path);
  void readSideState();
  // A row of the algorithm's round table: the update, env steps, the policy lag of the batch (in
  // updates: mean, max) and the algorithm's figures of the round.
  void appendRoundRow(double lag_mean, int64_t lag_max);
  // Every rank's parameters, normalizers and learning rate hash the same, or RankDisagreement.
  void checkRanksAgree();
  // Tells the update: the stats message, metrics.csv, the curve, the progress line.
  void report();
  bool curveHasData() const;  // every panel of the learning curve has a point to draw
  void openRunFiles();  // rank 0: config.yaml, metrics.csv and the TensorBoard event file (run_dir/run_files.hpp)
  void loadCheckpoint();
  void evaluate();
  double wallTime() const;

  config::RunConfig rc_;
  LearnerOptions opt_;
  std::string dir_;
  int64_t run_id_ = 0;

  Rng rng_;
  int obs_dim_ = 0, act_dim_ = 0;  // the task's (its symmetry spec's)
  std::unique_ptr<Algorithm> algorithm_;
  std::unique_ptr<rollout::RolloutBuffer> buffer_;  // the batch
  BatchOrigin origin_;  // where the batch's environments came from: their policy versions (the lag)
  std::vector<int64_t> env_streams_;  // each batch column's stream id (Algorithm::learn)

  cluster::Communicator* ranks_;
  int rank_envs_;  // this rank's environments of a full batch
  bool waiting_for_ranks_ = false;  // a batch is taken (or a stop asked); the ranks' barrier is pending
  bool ranks_stopped_ = false;      // the ranks agreed to stop
  bool entered_silent_ = false;     // this rank entered the barrier because it heard nothing for too long
  int silent_ranks_at_stop_ = 0;
  const std::atomic<bool>* stop_ = nullptr;  // run()'s
  std::unique_ptr<transport::MessageBus> owned_transport_;  // made from url / rollout_url (LCM)
  transport::MessageBus* transport_ = nullptr;              // the intake's: owned_transport_ or options.bus
  std::unique_ptr<transport::MessageBus> policy_transport_;  // rank 0, when the rollouts come on another URL
  std::unique_ptr<RolloutAssembler> assembler_;  // made once the run id is known
  std::unique_ptr<SilenceWatch> silence_;
  // Made on the first accepted chunk: the reward term names come from the actors' task.
  std::unique_ptr<BatchCollector> collector_;
  RoundTracker round_;   // when a batch may form short of lost chunks
  int min_batch_envs_;   // the fewest environments a short batch may have (> ppo.num_envs: never short)
  ParamsDelivery delivery_;  // which live actors hold the newest parameters (rank 0)
  int64_t unacknowledged_repeats_ = 0;

  int64_t updates_ = 0, env_steps_ = 0;
  double wall_offset_s_ = 0;  // wall time of the runs before a resume
  std::chrono::steady_clock::time_point start_, last_update_, last_publish_;
  std::chrono::steady_clock::time_point idle_since_;  // the end of the last update (or the start): what wait_s counts from
  std::unique_ptr<LearningCurve> curve_;  // made with the first update: it needs the reward terms
  // TensorBoard: the run's event file, fed with every row of metrics.csv and of the algorithm's round table (rank 0).
  std::unique_ptr<RunFiles> files_;  // config.yaml, metrics.csv and the events (rank 0)
  bool metrics_open_ = false;
  std::unique_ptr<CsvEvents> round_events_;
  int64_t max_updates_ = -1;              // of the current run(), for the ETA; -1: unknown
  double update_interval_s_ = 0;          // moving average of the wall time between updates
  UpdateReport report_;
  // The task, built once, for the evaluations of runner.eval_every (null when they are off).
  std::unique_ptr<task::TaskFactory> eval_factory_;
  ReportColumns columns_;  // reward terms (from the first chunk) and the task's progress figures
  bool has_success_ = true;  // the task measures success (the curve's success axis)
  std::function<void(int64_t)> checkpoint_hook_;
};

}  // namespace masa::learner
