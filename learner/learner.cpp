#include "learner/learner.hpp"

#include <cmath>
#include <omp.h>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "common/core/check.hpp"
#include "common/policy/policy_file.hpp"
#include "common/task/policy_evaluator.hpp"
#include "learner/checkpoint.hpp"
#include "learner/metrics_csv.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/drop_reason.hpp"
#include "masa/lcmt_learner_stats.hpp"
#include "masa/lcmt_policy_params.hpp"

namespace masa::learner {

namespace fs = std::filesystem;

namespace {

// RunningMeanStd's default epsilon: the broadcast std is sqrt(var + eps), what the learner divides by.
constexpr double kObsEps = 1e-5;


model::ModelConfig modelConfigOf(const config::RunConfig& rc) {
  model::ModelConfig m = rc.model;
  m.method = rc.method;  // the run's method is authoritative
  return m;
}

int64_t randomRunId() {
  // Clock-derived and mixed, so two learners started in the same second still differ.
  uint64_t x = static_cast<uint64_t>(std::chrono::high_resolution_clock::now().time_since_epoch().count());
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  return static_cast<int64_t>(x & 0x7fffffffffffffffULL) | 1;  // positive, never 0
}

transport::AssemblerConfig assemblerConfig(int64_t run_id, const config::RunConfig& rc, int obs_dim, int act_dim) {
  transport::AssemblerConfig a;
  a.run_id = run_id;
  a.horizon = rc.ppo.horizon;
  a.obs_dim = obs_dim;
  a.act_dim = act_dim;
  a.max_policy_lag = rc.ppo.max_policy_lag;
  return a;
}

}  // namespace

Learner::Learner(const config::RunConfig& rc, const LearnerOptions& options)
    : rc_(rc),
      opt_(options),
      dir_(options.run_dir),
      rng_(rc.seed) {
  MASA_CHECK(!dir_.empty(), "learner: no run directory");
  fs::create_directories(dir_);
  const auto spec = sym::SymmetrySpec::load(rc_.spec_path);
  model_ = std::make_unique<model::ActorCritic<float>>(spec, modelConfigOf(rc_));
  model_->initialize(rng_);
  nn::AdamConfig<float> adam_cfg;
  adam_cfg.lr = static_cast<float>(rc_.ppo.learning_rate);
  adam_ = std::make_unique<nn::Adam<float>>(model_->params(), adam_cfg);
  trainer_ = std::make_unique<ppo::PpoTrainer>(*model_, *adam_, rc_.ppo);
  buffer_ = std::make_unique<ppo::RolloutBuffer>(rc_.ppo.num_envs, rc_.ppo.horizon, model_->obsDim(), model_->actDim());

  run_id_ = options.run_id;
  if (opt_.resume) loadCheckpoint();  // sets run_id_ unless one was given
  // Rewritten on resume too: overrides given then are part of the run from now on.
  std::ofstream(fs::path(dir_) / "config.yaml") << config::dumpResolved(rc_);
  if (run_id_ == 0) run_id_ = randomRunId();
  assembler_ = std::make_unique<transport::RolloutAssembler>(assemblerConfig(run_id_, rc_, model_->obsDim(), model_->actDim()));
  assembler_->setLearnerVersion(version_);

  transport_ = std::make_unique<transport::Transport>(opt_.url, opt_.run_key);
  transport_->subscribeRaw(transport::kRolloutChannel, [this](const void* data, int size) { onChunk(data, size); });

  if (rc_.runner.eval_every > 0) {
    eval_factory_ = std::make_unique<task::TaskFactory>(rc_.task, spec, rc_.env, rc_.origin);
    eval_progress_names_ = eval_factory_->create()->progressNames();
  }

  start_ = last_update_ = std::chrono::steady_clock::now();
  silence_ = std::make_unique<SilenceWatch>(rc_.runner.silence_warn_s, start_);
  publishParams();
}

void Learner::evaluate() {
  // Fixed seeds, far from the actors' (each evaluation sees the same starts: curves compare).
  task::EvalOptions o;
  o.episodes = rc_.runner.eval_episodes;
  o.seed = 1000000;
  o.deterministic = true;
  o.threads = omp_get_max_threads();
  task::PolicyEvaluator evaluator(*eval_factory_, *model_);
  const task::EvalSummary s = evaluator.run(o);
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

transport::DropStats Learner::dropStats() const {
  transport::DropStats s = assembler_->stats();
  s.count[static_cast<int>(transport::DropReason::kUnauthenticated)] =
      transport_->rejected(transport::kRolloutChannel)[static_cast<int>(transport::WireVerdict::kUnauthenticated)];
  return s;
}

int64_t Learner::droppedChunks() const { return dropStats().dropped(); }

int64_t Learner::droppedEnvs() const {
  return collector_ ? collector_->stats().envs_stale + collector_->stats().envs_overflow : 0;
}

void Learner::onChunk(const void* data, int size) {
  const transport::Verdict v = assembler_->acceptEncoded(data, size);
  if (!v) return;  // counted by the assembler
  const auto& m = v.chunk->msg();
  silence_->heard(m.actor_id, std::chrono::steady_clock::now());
  if (!collector_) {
    transport::CollectorConfig c;
    c.num_envs = rc_.ppo.num_envs;
    c.horizon = rc_.ppo.horizon;
    c.obs_dim = model_->obsDim();
    c.act_dim = model_->actDim();
    c.max_policy_lag = rc_.ppo.max_policy_lag;
    c.term_names = m.term_names;
    collector_ = std::make_unique<transport::BatchCollector>(c);
    collector_->setLearnerVersion(version_);
  }
  collector_->add(*v.chunk);
}

bool Learner::step(int timeout_ms) {
  transport_->handleTimeout(timeout_ms);
  transport_->drain();
  bool updated = false;
  if (collector_ && collector_->take(batch_)) {
    update(batch_);
    updated = true;
  }
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - last_publish_).count() >= rc_.runner.republish_every_s) publishParams();
  if (auto warning = silence_->check(now, epoch_, droppedChunks())) std::cerr << *warning << "\n";
  return updated;
}

void Learner::run(int64_t max_updates, const std::atomic<bool>* stop) {
  max_updates_ = max_updates;
  while (epoch_ < max_updates && !(stop && stop->load())) step(100);
  writeCheckpoint();
  renderLearningCurve();
}

bool Learner::renderLearningCurve() { return curve_ && curve_->renderAndWait(); }

void Learner::fillBuffer(const transport::RolloutBatch& batch) {
  const transport::ActorRollout& d = batch.data;
  ppo::RolloutBuffer& b = *buffer_;
  const int E = d.num_envs, T = d.horizon, od = d.obs_dim, ad = d.act_dim;
  MASA_CHECK(E == b.numEnvs() && T == b.horizon() && od == b.obsDim() && ad == b.actDim(),
             "batch shape differs from the rollout buffer");
  const std::size_t steps = static_cast<std::size_t>(T) * E;
  // Both layouts are step-major (column t*E + e), so each array is one copy.
  std::memcpy(b.obs().data(), d.obs.data(), steps * od * sizeof(float));
  std::memcpy(b.bootstrapObs().data(), d.obsAt(T, 0), static_cast<std::size_t>(E) * od * sizeof(float));
  std::memcpy(b.actions().data(), d.actions.data(), steps * ad * sizeof(float));
  std::memcpy(b.means().data(), d.mean.data(), steps * ad * sizeof(float));
  std::memcpy(b.logProbs().data(), d.log_prob.data(), steps * sizeof(float));
  std::memcpy(b.rewards().data(), d.reward.data(), steps * sizeof(float));
  for (std::size_t i = 0; i < steps; ++i) {
    b.terminated().data()[i] = d.terminated[i] != 0;
    b.truncated().data()[i] = d.truncated[i] != 0;
  }
  // Each environment's own behaviour log-std: with max_policy_lag > 0 the batch mixes versions.
  MASA_CHECK(batch.env_log_std.size() == static_cast<std::size_t>(E) * ad, "batch without per-env log-std");
  for (int t = 0; t < T; ++t)
    for (int e = 0; e < E; ++e)
      b.logStds().col(b.column(t, e)) = Eigen::Map<const Vec<float>>(batch.env_log_std.data() + static_cast<std::size_t>(e) * ad, ad);
  b.clear();
  for (int i = 0; i < d.numFinal(); ++i) {
    const int idx = d.final_index[i];
    b.addFinalObs(idx / E, idx % E, Eigen::Map<const Mat<float>>(d.final_obs.data() + static_cast<std::size_t>(i) * od, od, 1));
  }
  b.checkFinalObs();
}

void Learner::summarizeEpisodes(const transport::ActorRollout& d) {
  const int n = d.numEpisodes(), K = d.numTerms();
  report_.num_episodes = n;
  report_.mean_return = report_.mean_length = 0;
  report_.term_means.assign(K, 0.0);
  int measured = 0, succeeded = 0;
  for (int i = 0; i < n; ++i) {
    report_.mean_return += d.episode_return[i];
    report_.mean_length += d.episode_length[i];
    if (d.episode_success[i] >= 0) {
      ++measured;
      succeeded += d.episode_success[i] == 1;
    }
    for (int k = 0; k < K; ++k) report_.term_means[k] += d.episode_term_sums[static_cast<std::size_t>(i) * K + k];
  }
  if (n > 0) {
    report_.mean_return /= n;
    report_.mean_length /= n;
    for (double& t : report_.term_means) t /= n;
  } else {
    // No episode ended in this batch: there is no return to report (0 would read as one).
    report_.mean_return = report_.mean_length = std::nan("");
    for (double& t : report_.term_means) t = std::nan("");
  }
  report_.success_rate = measured > 0 ? static_cast<double>(succeeded) / measured : -1.0;
}

void Learner::update(const transport::RolloutBatch& batch) {
  fillBuffer(batch);
  trainer_->prepare(*buffer_);
  if (!restored_order_.empty()) {
    // A resumed run continues the shuffle of the run it resumes (see PpoTrainer::shuffleOrder).
    if (restored_order_.size() == trainer_->shuffleOrder().size()) trainer_->shuffleOrder() = restored_order_;
    restored_order_.clear();
  }
  report_.ppo = trainer_->optimize(*buffer_, rng_);

  const auto now = std::chrono::steady_clock::now();
  const double dt = std::chrono::duration<double>(now - last_update_).count();
  last_update_ = now;
  const int64_t steps = static_cast<int64_t>(buffer_->size());
  env_steps_ += steps;
  report_.epoch = epoch_;
  ++epoch_;
  ++version_;
  report_.version = version_;
  report_.env_steps = env_steps_;
  report_.wall_time_s = wallTime();
  report_.fps = dt > 0 ? steps / dt : 0.0;
  // The first interval includes start-up; later ones weigh in with a short memory.
  update_interval_s_ = epoch_ <= 2 ? dt : 0.8 * update_interval_s_ + 0.2 * dt;
  summarizeEpisodes(batch.data);
  report_.dropped_chunks = droppedChunks();
  report_.dropped_envs = droppedEnvs();
  report_.eval_return = report_.eval_length = report_.eval_success = std::nan("");
  report_.eval_progress.assign(eval_progress_names_.size(), std::nan(""));
  if (eval_factory_ && epoch_ % rc_.runner.eval_every == 0) evaluate();

  assembler_->setLearnerVersion(version_);
  collector_->setLearnerVersion(version_);
  publishParams();
  publishStats();
  appendCsv();
  if (!curve_)
    curve_ = std::make_unique<LearningCurve>(dir_, rc_.task + " / " + model::methodName(rc_.method),
                                             collector_->config().term_names);
  if (rc_.runner.plot_every > 0 && epoch_ % rc_.runner.plot_every == 0) curve_->renderAsync();
  if (opt_.verbose) {
    char eta[32] = "";
    if (max_updates_ > epoch_) {
      const long remaining = std::lround(update_interval_s_ * static_cast<double>(max_updates_ - epoch_));
      std::snprintf(eta, sizeof(eta), "  eta %ld:%02ld:%02ld", remaining / 3600, remaining / 60 % 60, remaining % 60);
    }
    char total[32] = "";
    if (max_updates_ > 0) std::snprintf(total, sizeof(total), "/%lld", static_cast<long long>(max_updates_));
    char success[32] = "";  // only for tasks with a success notion
    if (report_.success_rate >= 0) std::snprintf(success, sizeof(success), "  success %.2f", report_.success_rate);
    std::printf("update %lld%s  steps %lld  fps %.0f  return %.3f  len %.1f%s  kl %.5f  lr %.2e  "
                "actor %.4f  critic %.4f  dropped %lld chunks %lld envs%s\n",
                static_cast<long long>(epoch_), total, static_cast<long long>(env_steps_), report_.fps,
                report_.mean_return, report_.mean_length, success, report_.ppo.kl, report_.ppo.lr,
                report_.ppo.actor_loss, report_.ppo.critic_loss, static_cast<long long>(report_.dropped_chunks), static_cast<long long>(report_.dropped_envs), eta);
    if (!std::isnan(report_.eval_return)) {
      std::printf("  eval (policy mean, %d episodes): return %.3f  len %.1f", rc_.runner.eval_episodes,
                  report_.eval_return, report_.eval_length);
      if (!std::isnan(report_.eval_success)) std::printf("  success %.2f", report_.eval_success);
      for (size_t i = 0; i < eval_progress_names_.size(); ++i)
        std::printf("  %s %.3f", eval_progress_names_[i].c_str(), report_.eval_progress[i]);
      std::printf("\n");
    }
    std::fflush(stdout);
  }
  if (rc_.runner.checkpoint_every > 0 && epoch_ % rc_.runner.checkpoint_every == 0) writeCheckpoint();
  if (rc_.runner.snapshot_every > 0 && epoch_ % rc_.runner.snapshot_every == 0) writeSnapshot();
}

void Learner::writeSnapshot() {
  // The policy of this stage, kept: offline datasets of many training stages ("mixed") are
  // recorded from them (masa_dataset families).
  const fs::path dir = fs::path(dir_) / "policies";
  fs::create_directories(dir);
  char name[32];
  std::snprintf(name, sizeof name, "policy_u%06lld.bin", static_cast<long long>(epoch_));
  policy::savePolicyFile((dir / name).string(), rc_, *model_);
}

void Learner::publishParams() {
  masa::lcmt_policy_params m;
  m.run_id = run_id_;
  m.utime = transport::wallClockMicros();
  m.version = version_;
  m.method = model::methodName(rc_.method);
  m.task = rc_.task;
  // The policy prefix only: the critic is the learner's business, and it halves the broadcast.
  const auto& p = model_->params().values();
  m.num_params = model_->policyParamCount();
  m.params.assign(p.data(), p.data() + m.num_params);
  if (model_->config().normalize_obs) {
    auto& norm = model_->obsNormalizer();
    m.obs_dim = norm.dim();
    m.obs_mean.resize(norm.dim());
    m.obs_std.resize(norm.dim());
    for (int d = 0; d < norm.dim(); ++d) {
      m.obs_mean[d] = static_cast<float>(norm.mean()(d));
      m.obs_std[d] = static_cast<float>(std::sqrt(norm.var()(d) + kObsEps));
    }
  } else {
    m.obs_dim = 0;
  }
  transport_->publish(transport::kPolicyChannel, m);
  last_publish_ = std::chrono::steady_clock::now();
}

void Learner::publishStats() {
  masa::lcmt_learner_stats s;
  s.run_id = run_id_;
  s.utime = transport::wallClockMicros();
  s.epoch = report_.epoch;
  s.version = report_.version;
  s.env_steps = report_.env_steps;
  s.fps = static_cast<float>(report_.fps);
  s.mean_episode_return = static_cast<float>(report_.mean_return);
  s.mean_episode_length = static_cast<float>(report_.mean_length);
  s.success_rate = static_cast<float>(report_.success_rate);
  s.num_episodes = report_.num_episodes;
  const ppo::PpoStats& p = report_.ppo;
  s.actor_loss = static_cast<float>(p.actor_loss);
  s.critic_loss = static_cast<float>(p.critic_loss);
  s.entropy = static_cast<float>(p.entropy);
  s.bounds_loss = static_cast<float>(p.bounds_loss);
  s.symmetry_policy_loss = static_cast<float>(p.sym_policy_loss);
  s.symmetry_value_loss = static_cast<float>(p.sym_value_loss);
  s.kl = static_cast<float>(p.kl);
  s.learning_rate = static_cast<float>(p.lr);
  s.grad_norm = static_cast<float>(p.grad_norm);
  s.explained_variance = static_cast<float>(p.explained_variance);
  // Chunk reasons, then the collector's own drops (environments).
  const transport::DropStats chunks = dropStats();
  for (int r = 1; r < transport::kNumDropReasons; ++r) {
    s.drop_reason_names.emplace_back(transport::dropReasonName(static_cast<transport::DropReason>(r)));
    s.drop_counts.push_back(chunks.count[r]);
  }
  s.drop_reason_names.emplace_back("stale_in_collector");
  s.drop_counts.push_back(collector_ ? collector_->stats().envs_stale : 0);
  s.drop_reason_names.emplace_back("overflow_in_collector");
  s.drop_counts.push_back(collector_ ? collector_->stats().envs_overflow : 0);
  s.num_drop_reasons = static_cast<int32_t>(s.drop_counts.size());
  if (collector_) s.term_names = collector_->config().term_names;
  s.num_terms = static_cast<int32_t>(s.term_names.size());
  for (int k = 0; k < s.num_terms; ++k)
    s.term_means.push_back(k < static_cast<int>(report_.term_means.size()) ? static_cast<float>(report_.term_means[k]) : 0.0f);
  transport_->publish(transport::kLearnerStatsChannel, s);
}

void Learner::appendCsv() {
  const fs::path path = fs::path(dir_) / "metrics.csv";
  const bool fresh = !fs::exists(path) || fs::file_size(path) == 0;
  std::ofstream f(path, std::ios::app);
  if (fresh) {
    f << "epoch,version,env_steps,wall_time_s,fps,return,length,success";
    if (collector_)
      for (const auto& t : collector_->config().term_names) f << ",term_" << t;
    f << ",actor_loss,critic_loss,entropy,bounds_loss,sym_policy,sym_value,kl,lr,grad_norm,explained_variance,dropped_chunks,dropped_envs";
    f << ",eval_return,eval_length,eval_success";
    for (const auto& n : eval_progress_names_) f << ",eval_" << n;
    f << '\n';
  }
  const ppo::PpoStats& p = report_.ppo;
  f.precision(9);
  f << report_.epoch << ',' << report_.version << ',' << report_.env_steps << ',' << report_.wall_time_s << ','
    << report_.fps << ',' << report_.mean_return << ',' << report_.mean_length << ',' << report_.success_rate;
  for (double t : report_.term_means) f << ',' << t;
  f << ',' << p.actor_loss << ',' << p.critic_loss << ',' << p.entropy << ',' << p.bounds_loss << ','
    << p.sym_policy_loss << ',' << p.sym_value_loss << ',' << p.kl << ',' << p.lr << ',' << p.grad_norm << ','
    << p.explained_variance << ',' << report_.dropped_chunks << ',' << report_.dropped_envs;
  f << ',' << report_.eval_return << ',' << report_.eval_length << ',' << report_.eval_success;
  for (double v : report_.eval_progress) f << ',' << v;
  f << '\n';
}

void Learner::writeCheckpoint() {
  CheckpointState s;
  s.run_id = run_id_;
  s.updates = epoch_;
  s.version = version_;
  s.env_steps = env_steps_;
  s.wall_time_s = wallTime();
  s.lr = trainer_->learningRate().lr();
  std::ostringstream rng_text;
  rng_text << rng_;
  s.rng_state = rng_text.str();
  s.order = trainer_->shuffleOrder();
  learner::writeCheckpoint((fs::path(dir_) / "checkpoint.bin").string(), s, *model_, *adam_);
  // What inference needs, for evaluation and deployment (masa_eval, the robot runner).
  policy::savePolicyFile((fs::path(dir_) / "policy.bin").string(), rc_, *model_);
}

void Learner::loadCheckpoint() {
  const CheckpointState s = readCheckpoint((fs::path(dir_) / "checkpoint.bin").string(), *model_, adam_.get());
  if (run_id_ == 0) run_id_ = s.run_id;  // keep the run: its actors go on being accepted
  epoch_ = s.updates;
  version_ = s.version;
  env_steps_ = s.env_steps;
  wall_offset_s_ = s.wall_time_s;
  std::istringstream rng_text(s.rng_state);
  rng_text >> rng_;
  if (!rng_text) throw std::runtime_error("resume: corrupt rng state in " + dir_ + "/checkpoint.bin");
  restored_order_ = s.order;
  truncateMetricsCsv((fs::path(dir_) / "metrics.csv").string(), s.updates);  // rows past the checkpoint come again
  trainer_->learningRate().setLr(s.lr);
  adam_->config().lr = static_cast<float>(s.lr);
}

}  // namespace masa::learner
