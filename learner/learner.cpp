#include "learner/learner.hpp"

#include <algorithm>
#include <cmath>
#include <omp.h>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "common/cluster/rank_agreement.hpp"
#include "common/core/binary_io.hpp"
#include "common/core/check.hpp"
#include "common/integrity/sealed_file.hpp"
#include "common/policy/policy_file.hpp"
#include "common/sim/policy_evaluator.hpp"
#include "learner/run_dir/checkpoint.hpp"
#include "learner/intake/drop_reason.hpp"
#include "learner/run_dir/metrics_csv.hpp"
#include "learner/run_dir/run_directory.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "common/transport/channels.hpp"
#include "masa/lcmt_policy_params.hpp"
#include "tasks/tasks.hpp"

namespace masa::learner {

namespace fs = std::filesystem;

namespace {

// An actor counts as live for the parameter repeats this long after it was last heard: three of its
// heartbeats (one a second). A dead actor costs the repeats of these seconds, then none.
constexpr double kActorLiveS = 3.0;


int64_t randomRunId() {
  // Clock-derived and mixed, so two learners started in the same second still differ.
  uint64_t x = static_cast<uint64_t>(std::chrono::high_resolution_clock::now().time_since_epoch().count());
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  return static_cast<int64_t>(x & 0x7fffffffffffffffULL) | 1;  // positive, never 0
}

AssemblerConfig assemblerConfig(int64_t run_id, const config::RunConfig& rc, int obs_dim, int act_dim,
                                std::vector<std::string> term_names) {
  AssemblerConfig a;
  a.term_names = std::move(term_names);
  a.run_id = run_id;
  a.horizon = rc.rollout.horizon;
  a.obs_dim = obs_dim;
  a.act_dim = act_dim;
  a.max_policy_lag = rc.rollout.max_policy_lag;
  return a;
}

}  // namespace

Learner::Learner(const config::RunConfig& rc, const LearnerOptions& options)
    : rc_(rc),
      opt_(options),
      dir_(options.run_dir),
      rng_(rc.seed),
      ranks_(options.ranks ? options.ranks : &cluster::soloCommunicator()),
      rank_envs_(rc.rollout.num_envs / ranks_->size()),
      round_(rc.runner.loss_grace_s),
      delivery_(rc.runner.repeat_unacknowledged_s, rc.runner.republish_every_s, kActorLiveS) {
  MASA_CHECK(!dir_.empty(), "learner: no run directory");
  MASA_CHECK(rc.rollout.num_envs % ranks_->size() == 0, rc.rollout.key("num_envs") << " " << rc.rollout.num_envs << " must divide among the "
                                                                     << ranks_->size() << " learner ranks");
  MASA_CHECK(opt_.rank_check_every > 0, "rank_check_every must be positive, got " << opt_.rank_check_every);
  min_batch_envs_ = static_cast<int>(std::ceil(rc.runner.min_batch_fraction * rank_envs_));
  if (isLeadRank() && !opt_.resume) refuseRunDirInUse(dir_);
  if (isLeadRank()) fs::create_directories(dir_);
  const auto spec = sym::SymmetrySpec::load(rc_.spec_path);
  obs_dim_ = spec.obsDim();
  act_dim_ = spec.actDim();
  MASA_CHECK(opt_.make_algorithm, "learner: no algorithm given (LearnerOptions::make_algorithm)");
  algorithm_ = opt_.make_algorithm(rc_, rng_, *ranks_);
  MASA_CHECK(ranks_->size() == 1 || algorithm_->dataParallel(),
             "learner: " << rc_.learner << " runs on one learner rank (" << ranks_->size() << " given)");
  buffer_ = std::make_unique<rollout::RolloutBuffer>(rank_envs_, rc_.rollout.horizon, obs_dim_, act_dim_);

  run_id_ = options.run_id;
  if (opt_.resume) loadCheckpoint();  // sets run_id_ unless one was given
  // Rewritten on resume too: overrides given then are part of the run from now on.
  if (isLeadRank()) {
    openRunFiles();
  }
  if (run_id_ == 0) run_id_ = randomRunId();
  if (ranks_->size() > 1) {
    // Rank 0's run id for every rank (the actors carry one), and the same start everywhere.
    run_id_ = ranks_->gather(run_id_)[0];
    checkRanksAgree();
  }
  // The task says its reward terms; a chunk that names others is dropped (they become column names
  // and gnuplot words).
  auto factory = std::make_unique<task::TaskFactory>(task::taskCatalog(), rc_.task, spec, rc_.env, rc_.origin);
  const auto probe = factory->create();
  columns_.term_names = probe->rewardTermNames();
  assembler_ = std::make_unique<RolloutAssembler>(
      assemblerConfig(run_id_, rc_, obs_dim_, act_dim_, columns_.term_names));
  assembler_->setLearnerVersion(updates_);

  const std::string intake_url = opt_.rollout_url.empty() ? opt_.url : opt_.rollout_url;
  if (opt_.bus) {
    MASA_CHECK(ranks_->size() == 1, "learner: an in-process bus serves one learner rank (" << ranks_->size() << " given)");
    transport_ = opt_.bus;
    // Chunks as the actor made them, judged by the same assembler, without encoding.
    transport_->subscribe<masa::lcmt_rollout_chunk>(
        transport::kRolloutChannel, [this](const masa::lcmt_rollout_chunk& m) { onChunk(assembler_->accept(m)); });
  } else {
    owned_transport_ = makeTransport(intake_url);
    transport_ = owned_transport_.get();
    if (isLeadRank() && intake_url != opt_.url) policy_transport_ = makeTransport(opt_.url);
    transport_->subscribeRaw(transport::kRolloutChannel,
                             [this](const void* data, int size) { onChunk(assembler_->acceptEncoded(data, size)); });
  }
  // Actors acknowledge parameters in their heartbeats, which they send on the parameters' URL:
  // rank 0 hears every actor of a data-parallel job there, not only those that feed its own URL.
  if (isLeadRank())
    publisher().subscribe<masa::lcmt_actor_heartbeat>(transport::kHeartbeatChannel,
                                                      [this](const masa::lcmt_actor_heartbeat& m) { onHeartbeat(m); });

  if (isLeadRank()) {
    has_success_ = probe->measuresSuccess();
    if (rc_.runner.eval_every > 0) {
      columns_.progress_names = probe->progressNames();
      eval_factory_ = std::move(factory);
    }
  }

  start_ = last_update_ = idle_since_ = std::chrono::steady_clock::now();
  silence_ = std::make_unique<SilenceWatch>(rc_.runner.silence_warn_s, start_);
  if (isLeadRank()) publishParams();
}

void Learner::evaluate() {
  // Fixed seeds, far from the actors' (each evaluation sees the same starts: curves compare).
  task::EvalOptions o;
  o.episodes = rc_.runner.eval_episodes;
  o.seed = 1000000;
  o.deterministic = true;
  o.threads = omp_get_max_threads();
  task::PolicyEvaluator evaluator(*eval_factory_, algorithm_->evaluationModel());
  // The actors' chunks are taken in meanwhile, not left to overflow the socket's receive buffer.
  int steps = 0;
  const auto take_chunks = [this, &steps](int, int, const task::Task&, bool) {
    if (++steps % 64 == 0) transport_->drain();
  };
  const task::EvalSummary s = evaluator.run(o, take_chunks);
  report_.eval_return = s.ret.mean;
  report_.eval_length = s.length.mean;
  report_.eval_success = s.success_rate >= 0 ? s.success_rate : std::nan("");
  report_.eval_progress.clear();
  for (const auto& m : s.progress) report_.eval_progress.push_back(m.mean);
}

Learner::~Learner() = default;

double Learner::wallTime() const {
  return wall_offset_s_ + std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::unique_ptr<transport::Transport> Learner::makeTransport(const std::string& url) const {
  if (opt_.signed_mode) return std::make_unique<transport::Transport>(url, *opt_.signed_mode);
  return std::make_unique<transport::Transport>(url, opt_.run_key);
}

DropStats Learner::dropStats() const {
  DropStats s = assembler_->stats();
  using transport::WireVerdict;
  const transport::WireRejects refused = transport_->rejected(transport::kRolloutChannel);
  for (const auto& [reason, verdict] : {std::pair{DropReason::kUnauthenticated, WireVerdict::kUnauthenticated},
                                        std::pair{DropReason::kUnknownSender, WireVerdict::kUnknownSender},
                                        std::pair{DropReason::kNotPermitted, WireVerdict::kNotPermitted},
                                        std::pair{DropReason::kClaimsAnotherActor, WireVerdict::kClaimsAnotherSender},
                                        std::pair{DropReason::kReplayed, WireVerdict::kReplayed},
                                        std::pair{DropReason::kBeyondWindow, WireVerdict::kBeyondWindow},
                                        std::pair{DropReason::kBeforeStart, WireVerdict::kBeforeStart},
                                        std::pair{DropReason::kAnotherRanksActor, WireVerdict::kAnotherRanksActor}})
    s.count[static_cast<int>(reason)] = refused[static_cast<int>(verdict)];
  return s;
}

int64_t Learner::droppedChunks() const { return dropStats().dropped(); }

int64_t Learner::droppedEnvs() const {
  return collector_ ? collector_->stats().envs_stale + collector_->stats().envs_overflow : 0;
}

void Learner::onChunk(const Verdict& v) {
  if (!v) return;  // counted by the assembler
  const auto& m = v.chunk->msg();
  const auto now = std::chrono::steady_clock::now();
  silence_->heard(m.actor_id, now);
  round_.chunkArrived(m.actor_id, m.rollout_seq, m.chunk_index, m.num_chunks, now);
  if (!collector_) {
    CollectorConfig c;
    c.num_envs = rank_envs_;
    c.horizon = rc_.rollout.horizon;
    c.obs_dim = obs_dim_;
    c.act_dim = act_dim_;
    c.max_policy_lag = rc_.rollout.max_policy_lag;
    c.term_names = columns_.term_names;  // the task's: the assembler dropped chunks naming others
    collector_ = std::make_unique<BatchCollector>(c);
    collector_->setLearnerVersion(updates_);
  }
  collector_->add(*v.chunk);
  delivery_.actorHolds(m.actor_id, m.policy_version, now);  // it acted with that version
}

void Learner::onHeartbeat(const masa::lcmt_actor_heartbeat& m) {
  // Authenticated and guarded by the transport; what it says is believed only within bounds. A
  // heartbeat moves nothing but the repeats of the parameters.
  if (m.run_id != run_id_ || m.actor_id < 0 || m.actor_id >= assembler_->config().max_actors) return;
  if (m.params_version < -1) return;
  delivery_.actorHolds(m.actor_id, m.params_version, std::chrono::steady_clock::now());
}

int Learner::waitMs(int timeout_ms) const {
  const auto now = std::chrono::steady_clock::now();
  auto due = std::chrono::steady_clock::time_point::max();
  if (collector_ && !collector_->ready() && collector_->bufferedEnvs() >= min_batch_envs_) due = round_.nextDeadline();
  if (isLeadRank()) due = std::min(due, delivery_.nextRepeat(now));
  if (due == std::chrono::steady_clock::time_point::max()) return timeout_ms;
  const double ms = std::chrono::duration<double, std::milli>(due - now).count();
  return static_cast<int>(std::clamp(std::ceil(ms), 0.0, static_cast<double>(timeout_ms)));
}

bool Learner::step(int timeout_ms) {
  transport_->handleTimeout(waiting_for_ranks_ ? std::min(timeout_ms, 1) : waitMs(timeout_ms));
  transport_->drain();
  if (policy_transport_) {  // rank 0 of several: the actors' heartbeats (acknowledgements)
    policy_transport_->handleTimeout(0);
    policy_transport_->drain();
  }
  bool updated = false;
  if (!waiting_for_ranks_) {
    bool batch = collector_ && collector_->take(*buffer_, &origin_);
    // The missing environments were lost: waiting would not bring them.
    if (!batch && collector_ && round_.settled(std::chrono::steady_clock::now()))
      batch = collector_->takeShort(*buffer_, min_batch_envs_, &origin_);
    const bool stopping = stop_ && stop_->load();
    // A rank whose actors died (or cannot reach its URL) would never bring a batch, and the others
    // would wait for it in the barrier for ever: after runner.rank_silence_stop_s it stops them all.
    entered_silent_ = !batch && ranks_->size() > 1 && rc_.runner.rank_silence_stop_s > 0 &&
                      silence_->silentFor(std::chrono::steady_clock::now()) >= rc_.runner.rank_silence_stop_s;
    if (entered_silent_)
      std::cerr << "masa_learner " << ranks_->describe() << ": no rollout data for "
                << silence_->silentFor(std::chrono::steady_clock::now()) << " s (runner.rank_silence_stop_s "
                << rc_.runner.rank_silence_stop_s << "): its actors died or cannot reach '"
                << (opt_.rollout_url.empty() ? opt_.url : opt_.rollout_url) << "'; stopping every rank" << std::endl;
    if (ranks_->size() > 1 && (batch || stopping || entered_silent_)) {
      // The update is collective: wait for every rank's batch (or stop), receiving chunks meanwhile.
      ranks_->beginBarrier();
      waiting_for_ranks_ = true;
    } else if (batch) {
      update();
      updated = true;
    }
  }
  if (waiting_for_ranks_ && ranks_->barrierDone()) {
    waiting_for_ranks_ = false;
    // Every rank is here with a batch or a stop: all stop together if any stops (a signal reaches
    // every rank of a job, but not at the same update), else all update.
    double stopping[2] = {stop_ && stop_->load() ? 1.0 : 0.0, entered_silent_ ? 1.0 : 0.0};
    ranks_->sum(stopping, 2);
    if (stopping[0] + stopping[1] > 0) {
      ranks_stopped_ = true;
      silent_ranks_at_stop_ = static_cast<int>(stopping[1]);
      if (silent_ranks_at_stop_ > 0 && isLeadRank())
        std::cerr << "masa_learner: the learner ranks stop at update " << updates_ << ": " << silent_ranks_at_stop_
                  << " of " << ranks_->size() << " heard no rollout data for " << rc_.runner.rank_silence_stop_s
                  << " s (see their messages); resume from the checkpoint once their actors run" << std::endl;
    } else {
      update();
      updated = true;
    }
  }
  const auto now = std::chrono::steady_clock::now();
  if (isLeadRank()) {
    if (std::chrono::duration<double>(now - last_publish_).count() >= rc_.runner.republish_every_s) {
      publishParams();
    } else if (delivery_.repeatDue(now)) {
      ++unacknowledged_repeats_;
      publishParams();
    }
  }
  if (auto warning = silence_->check(now, updates_, droppedChunks())) std::cerr << *warning << "\n";
  return updated;
}

void Learner::run(int64_t max_updates, const std::atomic<bool>* stop) {
  max_updates_ = max_updates;
  stop_ = stop;
  if (ranks_->size() == 1)
    while (updates_ < max_updates && !(stop && stop->load())) step(100);
  else  // ranks stop together (step())
    while (updates_ < max_updates && !ranks_stopped_) step(100);
  writeCheckpoint();
  renderLearningCurve();
}

bool Learner::renderLearningCurve() { return curve_ && curveHasData() && curve_->renderAndWait(); }

bool Learner::curveHasData() const {
  // gnuplot stops at a panel whose every point is NaN: no return before an episode ended, no mean
  // Q before the off-policy learner's first gradient step (a resumed run's CSV has its history).
  return (opt_.resume || report_.last_episodes_update > 0) && algorithm_->curveHasData();
}

void Learner::update() {
  // The learner reads no message while it updates: that time is not the actors' silence.
  struct ExcuseBusyTime {
    SilenceWatch& watch;
    std::chrono::steady_clock::time_point from = std::chrono::steady_clock::now();
    ~ExcuseBusyTime() { watch.learnerWasBusy(std::chrono::steady_clock::now() - from); }
  } excuse{*silence_};
  const auto began = std::chrono::steady_clock::now();
  report_.wait_s = std::chrono::duration<double>(began - idle_since_).count();
  struct MarkIdle {  // however update() returns (rank 0 publishes and reports; the others return early)
    std::chrono::steady_clock::time_point& since;
    ~MarkIdle() { since = std::chrono::steady_clock::now(); }
  } mark_idle{idle_since_};
  // How far behind the parameters being trained the batch's environments acted, in updates.
  double lag_mean = 0;
  int64_t lag_max = 0;
  for (int64_t v : origin_.env_version) {
    lag_mean += static_cast<double>(updates_ - v) / static_cast<double>(origin_.env_version.size());
    lag_max = std::max(lag_max, updates_ - v);
  }
  // An environment's stream: its actor and its index there (ids below 2^32 each).
  env_streams_.resize(origin_.env_actor.size());
  for (std::size_t e = 0; e < env_streams_.size(); ++e)
    env_streams_[e] = (static_cast<int64_t>(origin_.env_actor[e]) << 32) | static_cast<uint32_t>(origin_.env_index[e]);
  report_.learned = algorithm_->learn(*buffer_, env_streams_, rng_);
  report_.algorithm_figures = algorithm_->progressFigures(report_.learned);

  const auto now = std::chrono::steady_clock::now();
  report_.learn_s = std::chrono::duration<double>(now - began).count();
  const double dt = std::chrono::duration<double>(now - last_update_).count();
  last_update_ = now;
  int64_t steps = static_cast<int64_t>(buffer_->size());
  if (ranks_->size() > 1) {
    steps = 0;
    for (int64_t rank_steps : ranks_->gather(buffer_->size())) steps += rank_steps;
  }
  env_steps_ += steps;
  ++updates_;
  report_.update = updates_;
  report_.env_steps = env_steps_;
  report_.wall_time_s = wallTime();
  report_.fps = dt > 0 ? steps / dt : 0.0;
  // The first interval includes start-up; later ones weigh in with a short memory.
  update_interval_s_ = updates_ <= 2 ? dt : 0.8 * update_interval_s_ + 0.2 * dt;
  summarizeEpisodes(buffer_->data(), report_, *ranks_);
  double drops[2] = {static_cast<double>(droppedChunks()), static_cast<double>(droppedEnvs())};
  if (ranks_->size() > 1) ranks_->sum(drops, 2);  // every rank's, in metrics.csv and the progress line
  report_.dropped_chunks = static_cast<int64_t>(drops[0]);
  report_.dropped_envs = static_cast<int64_t>(drops[1]);
  report_.eval_return = report_.eval_length = report_.eval_success = std::nan("");
  report_.eval_progress.assign(columns_.progress_names.size(), std::nan(""));

  assembler_->setLearnerVersion(updates_);
  collector_->setLearnerVersion(updates_);
  round_.newRound();
  if (ranks_->size() > 1 && updates_ % opt_.rank_check_every == 0) checkRanksAgree();
  if (!isLeadRank()) return;  // rank 0 speaks for the ranks and keeps the run directory
  publishParams();
  // After the parameters went out, so that the actors collect while the policy is evaluated
  // (evaluated before, the actors waited past their limit and sent rollouts too old to use).
  if (eval_factory_ && updates_ % rc_.runner.eval_every == 0) evaluate();
  report();
  if (round_events_) {
    appendRoundRow(lag_mean, lag_max);
    round_events_->mirrorLastRow();
  }
  if (rc_.runner.checkpoint_every > 0 && updates_ % rc_.runner.checkpoint_every == 0) writeCheckpoint();
  if (rc_.runner.snapshot_every > 0 && updates_ % rc_.runner.snapshot_every == 0) writeSnapshot();
}

void Learner::openRunFiles() {
  // The configuration as text, at the step the run (re)starts from: a resume's overrides show.
  files_ = std::make_unique<RunFiles>(dir_, config::dumpResolved(rc_), env_steps_, RunFiles::Metrics{"env_steps", "learn"});
  if (const std::string table = algorithm_->roundTable(); !table.empty())
    round_events_ = std::make_unique<CsvEvents>(files_->events(), files_->path(table), "env_steps",
                                                fs::path(table).stem().string(), std::vector<std::string>{"update"});
}

void Learner::checkRanksAgree() {
  cluster::requireSameOnEveryRank(*ranks_, algorithm_->agreementHash(), "parameters, normalizers or learning rate after update " +
                                                 std::to_string(updates_));
}

void Learner::report() {
  const CollectorStats& c = collector_->stats();
  publisher().publish(transport::kLearnerStatsChannel,
                      statsMessage(report_, columns_, run_id_, dropStats(), c.envs_stale, c.envs_overflow));
  if (!metrics_open_) {
    // A resumed run's rows follow those kept to its checkpoint; a run that never reported starts the file.
    const fs::path csv = files_->path("metrics.csv");
    if (fs::exists(csv) && fs::file_size(csv) > 0) {
      files_->continueMetrics();
    } else {
      files_->startMetrics(metricsHeader(columns_));
    }
    metrics_open_ = true;
  }
  writeMetricsRow(files_->metrics(), report_);
  files_->endRow();
  if (!curve_)
    curve_ = std::make_unique<LearningCurve>(
        dir_, LearningCurve::Script{algorithm_->curveScript(rc_.task + " / " + model::methodName(rc_.method),
                                                            columns_.term_names, has_success_)});
  if (rc_.runner.plot_every > 0 && updates_ % rc_.runner.plot_every == 0 && curveHasData()) curve_->renderAsync();
  if (opt_.verbose) printProgress(report_, columns_, max_updates_, update_interval_s_, rc_.runner.eval_episodes);
}

void Learner::writeSnapshot() {
  // The policy of this stage, kept: offline datasets of many training stages ("mixed") are
  // recorded from them (masa_dataset families).
  const fs::path dir = fs::path(dir_) / "policies";
  fs::create_directories(dir);
  char name[32];
  std::snprintf(name, sizeof name, "policy_u%06lld.bin", static_cast<long long>(updates_));
  algorithm_->savePolicyFile((dir / name).string());
}

void Learner::publishParams() {
  masa::lcmt_policy_params m;
  m.run_id = run_id_;
  m.utime = transport::wallClockMicros();
  m.version = updates_;
  m.method = model::methodName(rc_.method);
  m.task = rc_.task;
  algorithm_->fillPolicyMessage(m);
  publisher().publish(transport::kPolicyChannel, m);
  last_publish_ = std::chrono::steady_clock::now();
  delivery_.published(m.version, last_publish_);
}

void Learner::writeCheckpoint() {
  if (!isLeadRank()) return;
  CheckpointState s;
  s.run_id = run_id_;
  s.updates = updates_;
  s.version = updates_;
  s.env_steps = env_steps_;
  s.wall_time_s = wallTime();
  std::ostringstream rng_text;
  rng_text << rng_;
  s.rng_state = rng_text.str();
  s.kind = algorithm_->kind();
  std::ostringstream body(std::ios::binary);
  algorithm_->saveCheckpointBody(body);
  s.body = std::move(body).str();
  // Two files, no common atomic write: the side state goes beside the old one (next), then
  // checkpoint.bin, then the next state takes the old one's name. A stop between any two steps
  // leaves a pair of the same update (readSideState sorts out which).
  const bool side = algorithm_->sideState().has_value();
  if (side) writeSideState(sideStatePath(true));
  learner::writeCheckpoint((fs::path(dir_) / "checkpoint.bin").string(), s);
  if (side) fs::rename(sideStatePath(true), sideStatePath(false));
  // What inference needs, for evaluation and deployment (masa_eval, the robot runner).
  algorithm_->savePolicyFile((fs::path(dir_) / "policy.bin").string());
  if (checkpoint_hook_) checkpoint_hook_(updates_);
}

void Learner::loadCheckpoint() {
  const std::string path = (fs::path(dir_) / "checkpoint.bin").string();
  CheckpointState s;
  if (ranks_->size() == 1) {
    s = readCheckpoint(path);
  } else {
    // Rank 0's file for every rank: the ranks need not share a file system.
    std::vector<uint8_t> bytes;
    if (isLeadRank()) {
      std::ifstream in(path, std::ios::binary);
      if (!in) throw std::runtime_error(path + ": cannot open the checkpoint");
      bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    ranks_->broadcast(bytes, 0);
    s = readCheckpointBytes(std::string(bytes.begin(), bytes.end()), path + " (rank 0's)");
  }
  if (run_id_ == 0) run_id_ = s.run_id;  // keep the run: its actors go on being accepted
  if (s.version != s.updates)
    throw std::runtime_error("resume: " + dir_ + "/checkpoint.bin has policy version " + std::to_string(s.version) +
                             " after " + std::to_string(s.updates) + " updates; they are one count");
  // A version 1 checkpoint held a PPO body in every run; an off-policy run never used it.
  const bool unused_legacy_body = s.legacy && s.kind != algorithm_->kind();
  if (s.kind != algorithm_->kind() && !unused_legacy_body)
    throw std::runtime_error("resume: " + path + " is of a run with learner: " + s.kind + "; this run's learner is " +
                             algorithm_->kind());
  updates_ = s.updates;
  env_steps_ = s.env_steps;
  wall_offset_s_ = s.wall_time_s;
  std::istringstream rng_text(s.rng_state);
  rng_text >> rng_;
  if (!rng_text) throw std::runtime_error("resume: corrupt rng state in " + dir_ + "/checkpoint.bin");
  if (!unused_legacy_body) {
    std::istringstream body(s.body, std::ios::binary);
    algorithm_->loadCheckpointBody(body, path);
  }
  if (isLeadRank()) {
    truncateMetricsCsv((fs::path(dir_) / "metrics.csv").string(), s.updates);  // rows past the checkpoint come again
    truncateEventFile((fs::path(dir_) / EventFile::kFileName).string(), s.env_steps);  // and their events
  }
  if (algorithm_->sideState()) readSideState();
  if (const std::string table = algorithm_->roundTable(); !table.empty() && isLeadRank())
    truncateMetricsCsv((fs::path(dir_) / table).string(), updates_);  // rows past the checkpoint come again
}

std::string Learner::sideStatePath(bool next) const {
  fs::path name = algorithm_->sideState()->name;
  if (next) name = name.stem().string() + ".next" + name.extension().string();
  return (fs::path(dir_) / name).string();
}

void Learner::writeSideState(const std::string& path) {
  // Streamed: a replay (most of a gigabyte) goes to the disk as it is hashed, never copied whole.
  integrity::writeSealedFileStreamed(path, algorithm_->sideState()->kind, [&](std::ostream& os) {
    io::writePod(os, updates_);
    algorithm_->saveSideState(os);
  });
}

void Learner::appendRoundRow(double lag_mean, int64_t lag_max) {
  const fs::path path = fs::path(dir_) / algorithm_->roundTable();
  const bool fresh = !fs::exists(path) || fs::file_size(path) == 0;
  std::ofstream f(path, std::ios::app);
  const auto figures = algorithm_->roundFigures();
  if (fresh) {
    f << "update,env_steps,policy_lag_mean,policy_lag_max";
    for (const auto& [name, value] : figures) f << ',' << name;
    f << '\n';
  }
  f.precision(9);
  f << updates_ << ',' << env_steps_ << ',' << lag_mean << ',' << lag_max;
  for (const auto& [name, value] : figures) f << ',' << value;
  f << '\n';
}

void Learner::readSideState() {
  // A next state is left by a stop inside writeCheckpoint: it is the one to go on from when
  // checkpoint.bin got to its update too, and a stale one otherwise (the stop fell before
  // checkpoint.bin was replaced).
  const integrity::FileKind kind = algorithm_->sideState()->kind;
  const std::string next = sideStatePath(true);
  const std::string path = sideStatePath(false);
  std::istringstream is;
  int64_t updates = -1;
  if (fs::exists(next)) {
    is.str(integrity::readSealedFile(next, kind).payload);
    if (!io::readPod(is, updates)) throw std::runtime_error(next + ": truncated");
    if (updates == updates_) {
      fs::rename(next, path);
    } else {
      std::fprintf(stderr, "masa_train: %s is of update %lld, checkpoint.bin of %lld: a stop fell before the checkpoint was written; going on from %s\n",
                   next.c_str(), static_cast<long long>(updates), static_cast<long long>(updates_), path.c_str());
      fs::remove(next);
      updates = -1;
    }
  }
  if (updates == -1) {
    is.str(integrity::readSealedFile(path, kind).payload);
    is.clear();
    if (!io::readPod(is, updates)) throw std::runtime_error(path + ": truncated");
  }
  if (updates != updates_)
    throw std::runtime_error("resume: " + path + " is of update " + std::to_string(updates) + ", checkpoint.bin of " +
                             std::to_string(updates_) + " (stopped while writing them?)");
  algorithm_->loadSideState(is, path);
}

}  // namespace masa::learner
