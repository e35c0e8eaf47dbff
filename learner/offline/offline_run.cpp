#include "learner/offline/offline_run.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "common/model/method.hpp"
#include "common/policy/policy_file.hpp"
#include "learner/run_dir/run_files.hpp"
#include "learner/run_dir/event_file.hpp"
#include "learner/run_dir/learning_curve.hpp"
#include "learner/offline/bc_trainer.hpp"
#include "learner/offline/iql_trainer.hpp"
#include "learner/offline/normalizer_fit.hpp"
#include "learner/offline/offline_curve.hpp"
#include "learner/offline/symmetry_augmentation.hpp"
#include "tasks/tasks.hpp"

namespace masa::offline {
namespace fs = std::filesystem;

namespace {
// The learner's evaluation seeds: far from any recording's, the same at every evaluation.
constexpr uint64_t kEvalSeed = 1000000;

std::string duration(double s) {
  char b[32];
  if (s >= 3600) std::snprintf(b, sizeof b, "%dh%02dm", static_cast<int>(s / 3600), static_cast<int>(s / 60) % 60);
  else if (s >= 60) std::snprintf(b, sizeof b, "%dm%02ds", static_cast<int>(s / 60), static_cast<int>(s) % 60);
  else std::snprintf(b, sizeof b, "%.0fs", s);
  return b;
}
}  // namespace

void checkDatasetFitsRun(const dataset::TransitionDataset& data, const config::RunConfig& rc,
                         const sym::SymmetrySpec& spec) {
  if (data.size() == 0) throw std::runtime_error("the dataset is empty: no transition to learn from");
  if (!data.task.empty() && data.task != rc.task)
    throw std::runtime_error("the dataset was recorded in task '" + data.task + "', the run is configured for '" +
                             rc.task + "'");
  if (data.obs_dim != spec.obsDim() || data.act_dim != spec.actDim())
    throw std::runtime_error("the dataset has " + std::to_string(data.obs_dim) + " observation and " +
                             std::to_string(data.act_dim) + " action entries, task " + rc.task + "'s spec " +
                             std::to_string(spec.obsDim()) + " and " + std::to_string(spec.actDim()));
  data.validate();
}

struct OfflineRun::Impl {
  config::RunConfig rc;
  OfflineConfig oc;
  OfflineRunOptions opt;
  sym::SymmetrySpec spec;
  dataset::TransitionDataset data;
  Rng rng;
  model::ActorCritic<float> model;
  std::unique_ptr<TwinQ<float>> q, q_target;
  std::unique_ptr<BcTrainer<float>> bc;
  std::unique_ptr<IqlTrainer<float>> iql;
  std::vector<std::string> losses, figures;  // metrics.csv columns of the algorithm
  std::vector<double> sums;                  // their sums since the last row
  std::unique_ptr<task::TaskFactory> factory;
  std::vector<std::string> progress_names;
  std::unique_ptr<learner::RunFiles> files;  // config.yaml, metrics.csv and their TensorBoard events
  std::unique_ptr<learner::LearningCurve> curve;
  double reward_scale = 1.0;  // IQL's TD target multiplies rewards by it

  Impl(const config::RunConfig& config, dataset::TransitionDataset d, OfflineRunOptions o)
      : rc(config),
        oc(readOfflineConfig(config)),
        opt(std::move(o)),
        spec(sym::SymmetrySpec::load(config.spec_path)),
        data(std::move(d)),
        rng(config.seed),
        model(spec, config.model) {
    checkDatasetFitsRun(data, rc, spec);
    if (oc.augment) data = augmentWithSymmetricImages(data, spec);
    model.initialize(rng);
    if (rc.model.normalize_obs) fitObservationNormalizer(model, data);
    if (oc.algo == Algo::kBc) {
      bc = std::make_unique<BcTrainer<float>>(model, oc);
      losses = {"bc_loss"};
      figures = {"mean_log_std"};
    } else {
      q = std::make_unique<TwinQ<float>>(spec, rc.method, oc.q_hidden, rc.model.activation);
      q_target = std::make_unique<TwinQ<float>>(spec, rc.method, oc.q_hidden, rc.model.activation);
      q->initialize(rng);
      q_target->moveTowards(*q, 1.0f);
      reward_scale = oc.normalize_reward ? rewardScaleForReturns(data) : 1.0;
      iql = std::make_unique<IqlTrainer<float>>(model, *q, *q_target, oc, reward_scale);
      losses = {"value_loss", "actor_loss", "q_loss"};
      figures = {"mean_q", "mean_v", "mean_advantage", "mean_weight"};
    }
    sums.assign(losses.size() + figures.size() + (iql ? 1 : 0), 0.0);
    factory = std::make_unique<task::TaskFactory>(task::taskCatalog(), rc.task, spec, rc.env, rc.origin);
    progress_names = factory->create()->progressNames();
    openRunDir();
  }

  void openRunDir() {
    files = std::make_unique<learner::RunFiles>(opt.run_dir, config::dumpResolved(rc), 0,
                                                learner::RunFiles::Metrics{"step", "offline"});
    std::vector<std::string> header{"step", "wall_s", "steps_per_s"};
    header.insert(header.end(), losses.begin(), losses.end());
    header.insert(header.end(), figures.begin(), figures.end());
    if (iql) header.push_back("actor_lr");
    for (const char* n : {"eval_return", "eval_length", "eval_success"}) header.push_back(n);
    for (const auto& n : progress_names) header.push_back("eval_" + n);
    files->startMetrics(header);
    const std::string title = rc.task + "  " + algoName(oc.algo) + " / " +
                              (oc.augment ? std::string("sasa-data") : model::methodName(rc.method)) + "  seed " +
                              std::to_string(rc.seed) + "  (" + std::to_string(data.size()) + " transitions)";
    curve = std::make_unique<learner::LearningCurve>(opt.run_dir,
                                                     learner::LearningCurve::Script{offlineCurveScript(
                                                         title, losses, figures,
                                                         oc.eval_every > 0 || oc.final_eval_episodes > 0)});
  }

  void step(const TransitionBatch<float>& batch) {
    size_t k = 0;
    if (bc) {
      const BcStats s = bc->step(batch);
      for (double v : {s.loss, s.mean_log_std}) sums[k++] += v;
    } else {
      const IqlStats s = iql->step(batch);
      for (double v : {s.value_loss, s.actor_loss, s.q_loss, s.mean_q, s.mean_v, s.mean_advantage, s.mean_weight,
                       s.actor_lr})
        sums[k++] += v;
    }
  }

  task::EvalSummary evaluate(int episodes) {
    task::EvalOptions o;
    o.episodes = episodes;
    o.seed = kEvalSeed;
    o.deterministic = true;
    o.threads = opt.eval_threads;
    task::PolicyEvaluator evaluator(*factory, model);
    const task::EvalSummary s = evaluator.run(o);
    policy::savePolicyFile((fs::path(opt.run_dir) / "policy.bin").string(), rc, model);
    return s;
  }

  void writeRow(long long step, double wall, double sps, int steps_in_row, const task::EvalSummary* eval) {
    std::ofstream& csv = files->metrics();
    csv << step << ',' << wall << ',' << sps;
    for (double& v : sums) {
      csv << ',' << (steps_in_row > 0 ? v / steps_in_row : std::nan(""));
      v = 0;
    }
    if (eval) {
      csv << ',' << eval->ret.mean << ',' << eval->length.mean << ','
          << (eval->success_rate >= 0 ? eval->success_rate : std::nan(""));
      for (const auto& m : eval->progress) csv << ',' << m.mean;
    } else {
      csv << ",nan,nan,nan";
      for (size_t i = 0; i < progress_names.size(); ++i) csv << ",nan";
    }
    csv << '\n';
    files->endRow();
  }

  void printProgress(long long step, double wall, double sps, int steps_in_row, const task::EvalSummary* eval) const {
    if (!opt.verbose) return;
    std::printf("step %lld/%lld (%.0f%%)  %.0f steps/s  elapsed %s  ETA %s", step, oc.steps, 100.0 * step / oc.steps,
                sps, duration(wall).c_str(), duration(sps > 0 ? (oc.steps - step) / sps : 0).c_str());
    for (size_t i = 0; i < losses.size() && steps_in_row > 0; ++i)
      std::printf("  %s %.4g", losses[i].c_str(), sums[i] / steps_in_row);
    if (eval) {
      std::printf("\n  eval (policy mean, %zu episodes): return %.3f  len %.1f", eval->episodes.size(), eval->ret.mean,
                  eval->length.mean);
      if (eval->success_rate >= 0) std::printf("  success %.2f", eval->success_rate);
    }
    std::printf("\n");
    std::fflush(stdout);
  }
};

OfflineRun::OfflineRun(const config::RunConfig& rc, dataset::TransitionDataset data, OfflineRunOptions options)
    : impl_(std::make_unique<Impl>(rc, std::move(data), std::move(options))) {}

OfflineRun::~OfflineRun() = default;

task::EvalSummary OfflineRun::run() {
  Impl& m = *impl_;
  if (m.opt.verbose) {
    std::printf("%s offline: %s / %s on %lld transitions (%zu episodes), %lld steps of batch %d -> %s\n",
                m.rc.task.c_str(), algoName(m.oc.algo).c_str(),
                m.oc.augment ? "sasa-data" : model::methodName(m.rc.method).c_str(), static_cast<long long>(m.data.size()),
                m.data.episodes.size(), m.oc.steps, m.oc.batch_size, m.opt.run_dir.c_str());
    if (m.iql) std::printf("  rewards x %.4g in the TD target (offline.normalize_reward)\n", m.reward_scale);
  }
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto row_start = t0;
  double train_s = 0;  // time in gradient steps only: evaluations do not count against the rate
  int steps_in_row = 0;
  TransitionBatch<float> batch;
  for (long long s = 1; s <= m.oc.steps; ++s) {
    sampleBatch(m.data, m.oc.batch_size, m.rng, batch);
    m.step(batch);
    ++steps_in_row;
    const bool eval_now = m.oc.eval_every > 0 && s % m.oc.eval_every == 0 && s < m.oc.steps;
    if (s % m.oc.log_every != 0 && !eval_now && s < m.oc.steps) continue;
    const auto now = Clock::now();
    train_s += std::chrono::duration<double>(now - row_start).count();
    const double sps = s / std::max(train_s, 1e-9);
    const double wall = std::chrono::duration<double>(now - t0).count();
    task::EvalSummary eval;
    if (eval_now) eval = m.evaluate(m.oc.eval_episodes);
    m.printProgress(s, wall, sps, steps_in_row, eval_now ? &eval : nullptr);
    m.writeRow(s, wall, sps, steps_in_row, eval_now ? &eval : nullptr);
    if (eval_now) m.curve->renderAsync();
    steps_in_row = 0;
    row_start = Clock::now();
  }
  task::EvalSummary final_eval;
  if (m.oc.final_eval_episodes > 0) {
    final_eval = m.evaluate(m.oc.final_eval_episodes);
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    m.writeRow(m.oc.steps, wall, m.oc.steps / std::max(train_s, 1e-9), 0, &final_eval);
    const std::string summary = task::formatSummary(final_eval);
    std::ofstream(fs::path(m.opt.run_dir) / "eval.txt") << summary;
    if (m.opt.verbose) std::printf("final evaluation (policy mean):\n%s", summary.c_str());
  } else {
    policy::savePolicyFile((fs::path(m.opt.run_dir) / "policy.bin").string(), m.rc, m.model);
  }
  m.curve->renderAndWait();
  if (m.opt.verbose) std::printf("wrote %s/{config.yaml,metrics.csv,policy.bin,learning_curve.png}\n", m.opt.run_dir.c_str());
  return final_eval;
}

}  // namespace masa::offline
