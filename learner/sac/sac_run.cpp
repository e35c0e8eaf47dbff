#include "learner/sac/sac_run.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>

#include "common/core/binary_io.hpp"
#include "common/model/method.hpp"
#include "common/sim/registry.hpp"
#include "learner/run_dir/event_file.hpp"
#include "learner/run_dir/run_files.hpp"
#include "learner/run_dir/run_directory.hpp"
#include "learner/sac/hindsight.hpp"
#include "learner/sac/sac_critic_maps.hpp"
#include "learner/sac/sac_policy_file.hpp"
#include "learner/sac/trainer_factory.hpp"
#include "tasks/tasks.hpp"

namespace masa::sac {
namespace fs = std::filesystem;

namespace {
// The learner's evaluation seeds: the same at every evaluation, far from the training resets.
constexpr uint64_t kEvalSeed = 1000000;

std::string duration(double s) {
  char b[32];
  if (s >= 3600) std::snprintf(b, sizeof b, "%dh%02dm", static_cast<int>(s / 3600), static_cast<int>(s / 60) % 60);
  else if (s >= 60) std::snprintf(b, sizeof b, "%dm%02ds", static_cast<int>(s / 60), static_cast<int>(s) % 60);
  else std::snprintf(b, sizeof b, "%.0fs", s);
  return b;
}

}  // namespace

struct SacRun::Impl {
  config::RunConfig rc;
  SacConfig sc;
  SacRunOptions opt;
  sym::SymmetrySpec spec;
  Rng rng;  // initialization, resets, exploration and the learner's noise and samples, in order
  SacPolicy<float> policy;
  offline::TwinQ<float> q, q_target;
  std::unique_ptr<OffPolicyTrainer<float>> trainer;  // SAC's or TD3's
  ReplayBuffer replay;
  std::unique_ptr<task::TaskFactory> factory;
  std::unique_ptr<task::Task> env;
  std::unique_ptr<Hindsight> hindsight;  // goal relabeling of the batches (off: the replay's own draws)
  std::vector<std::string> progress_names;
  std::unique_ptr<learner::RunFiles> files;  // config.yaml, metrics.csv and their TensorBoard events
  long long t_done = 0;    // environment steps taken
  std::vector<float> obs;  // the observation the next action is chosen from

  Impl(const config::RunConfig& config, SacRunOptions o)
      : rc(config),
        sc(readSacConfig(config)),
        opt(std::move(o)),
        spec(sym::SymmetrySpec::load(config.spec_path)),
        rng(config.seed),
        policy(spec, policyShape(config, sc)),
        q(spec, twinQMaps(config.method, spec), sc.q_hidden, config.model.activation),
        q_target(spec, twinQMaps(config.method, spec), sc.q_hidden, config.model.activation),
        replay(spec.obsDim(), spec.actDim(), sc.buffer_size) {
    policy.initialize(rng, static_cast<float>(rc.model.policy_last_layer_scale));  // 0.01 by default
    q.initialize(rng);
    q_target.moveTowards(q, 1.0f);
    trainer = makeTrainer(sc, spec, policy, q, q_target);  // after the initialization: TD3 copies the policy
    factory = std::make_unique<task::TaskFactory>(task::taskCatalog(), rc.task, spec, rc.env, rc.origin);
    env = factory->create();
    hindsight = std::make_unique<Hindsight>(rc, sc, env->goalRelabeling(), spec);
    progress_names = env->progressNames();
    obs.resize(spec.obsDim());
    if (!opt.resume) learner::refuseRunDirInUse(opt.run_dir);
    const learner::RunFiles::Metrics columns{"env_step", sc.algorithm};
    if (opt.resume) {
      loadState();
      learner::truncateEventFile((fs::path(opt.run_dir) / learner::EventFile::kFileName).string(), t_done);
      files = std::make_unique<learner::RunFiles>(opt.run_dir, config::dumpResolved(rc), t_done, columns);
      files->continueMetrics();
      return;
    }
    env->reset(rng);
    env->observe(obs.data());
    files = std::make_unique<learner::RunFiles>(opt.run_dir, config::dumpResolved(rc), 0, columns);
    std::vector<std::string> header{"env_step", "updates",   "wall_s", "env_steps_per_s", "train_return", "train_length",
                                    "episodes", "q_loss",    "actor_loss", "alpha_loss", "symmetry_loss", "alpha",
                                    "mean_q",   "entropy",   "eval_return", "eval_length"};
    for (const auto& n : progress_names) header.push_back("eval_" + n);
    files->startMetrics(header);
  }

  static constexpr char kMagic[8] = {'M', 'A', 'S', 'A', 'S', 'R', 'U', 'N'};

  // Written to a temporary file and renamed: a run stopped while saving keeps its last state.
  void saveState() {
    const fs::path path = fs::path(opt.run_dir) / "sac_state.bin", tmp = path.string() + ".tmp";
    {
      std::ofstream f(tmp, std::ios::binary);
      f.write(kMagic, sizeof kMagic);
      io::writePod(f, t_done);
      trainer->save(f);
      replay.save(f);
      std::vector<double> task_state;
      env->saveState(task_state);
      const long long n = static_cast<long long>(task_state.size());
      io::writePod(f, n);
      f.write(reinterpret_cast<const char*>(task_state.data()), static_cast<std::streamsize>(sizeof(double) * n));
      f.write(reinterpret_cast<const char*>(obs.data()), static_cast<std::streamsize>(sizeof(float) * obs.size()));
      f << rng << '\n';
      if (!f) throw std::runtime_error(tmp.string() + ": cannot write");
    }
    fs::rename(tmp, path);
  }

  void loadState() {
    const fs::path path = fs::path(opt.run_dir) / "sac_state.bin";
    std::ifstream f(path, std::ios::binary);
    char magic[8] = {};
    f.read(magic, sizeof magic);
    if (!f || std::string(magic, 8) != std::string(kMagic, 8)) throw std::runtime_error(path.string() + ": not a SAC run state");
    long long n = 0;
    if (!io::readPod(f, t_done)) throw std::runtime_error(path.string() + ": truncated");
    trainer->load(f);
    replay.load(f);
    if (!io::readPod(f, n) || n < 0 || n > (1 << 24)) throw std::runtime_error(path.string() + ": corrupt task state");
    std::vector<double> task_state(static_cast<size_t>(n));
    f.read(reinterpret_cast<char*>(task_state.data()), static_cast<std::streamsize>(sizeof(double) * n));
    f.read(reinterpret_cast<char*>(obs.data()), static_cast<std::streamsize>(sizeof(float) * obs.size()));
    f >> rng;
    if (!f) throw std::runtime_error(path.string() + ": truncated");
    env->loadState(task_state);
    if (t_done > sc.env_steps)
      throw std::runtime_error(path.string() + ": the run has taken " + std::to_string(t_done) +
                               " steps already, more than sac.env_steps (" + std::to_string(sc.env_steps) + ")");
  }

  // The normalizer from the stored (random-action) observations, then fixed.
  void fitNormalizer() {
    if (!rc.model.normalize_obs) return;
    Mat<float> chunk(spec.obsDim(), 1);
    const long long n = replay.size();
    constexpr long long kChunk = 4096;
    for (long long at = 0; at < n; at += kChunk) {
      const long long len = std::min(kChunk, n - at);
      chunk.resize(spec.obsDim(), len);
      for (long long j = 0; j < len; ++j)
        chunk.col(j) = Eigen::Map<const Eigen::VectorXf>(replay.obsAt(at + j), spec.obsDim());
      policy.obsNormalizer().update(chunk);
    }
    policy.setNormalizes(true);
  }

  struct Eval {
    double ret = 0, length = 0;
    std::vector<double> progress;
  };
  Eval evaluate() {
    Eval e;
    e.progress.assign(progress_names.size(), 0.0);
    auto task = factory->create();
    std::vector<float> obs(spec.obsDim()), act(spec.actDim());
    std::vector<double> prog(progress_names.size());
    for (int k = 0; k < sc.eval_episodes; ++k) {
      Rng er(kEvalSeed + k);
      task->reset(er);
      for (;;) {
        task->observe(obs.data());
        policy.actDeterministic(Eigen::Map<const Mat<float>>(obs.data(), spec.obsDim(), 1),
                                Eigen::Map<Mat<float>>(act.data(), spec.actDim(), 1));
        const task::StepOutcome out = task->step(act.data());
        if (out.terminated || out.truncated) break;
      }
      e.ret += task->episode().ret / sc.eval_episodes;
      e.length += static_cast<double>(task->episode().length) / sc.eval_episodes;
      if (!prog.empty()) {
        task->progress(prog.data());
        for (size_t i = 0; i < prog.size(); ++i) e.progress[i] += prog[i] / sc.eval_episodes;
      }
    }
    saveSacPolicyFile((fs::path(opt.run_dir) / "policy.bin").string(), rc, sc, policy, spec);
    return e;
  }
};

SacRun::SacRun(const config::RunConfig& rc, SacRunOptions options)
    : impl_(std::make_unique<Impl>(rc, std::move(options))) {}
SacRun::~SacRun() = default;

SacRunResult SacRun::run() {
  Impl& m = *impl_;
  const SacConfig& sc = m.sc;
  const int od = m.spec.obsDim(), ad = m.spec.actDim();
  if (m.opt.verbose)
    std::printf("%s %s / %s seed %llu: %lld env steps, %lld random first, %g update(s) per step of batch %d, n-step %d "
                "-> %s\n",
                m.rc.task.c_str(), sc.algorithm == "td3" ? "TD3" : "SAC", model::methodName(m.rc.method).c_str(),
                static_cast<unsigned long long>(m.rc.seed),
                sc.env_steps, sc.learning_starts, sc.updates_per_step, sc.batch_size, sc.n_step, m.opt.run_dir.c_str());
  if (m.opt.verbose && m.hindsight->enabled())
    std::printf("hindsight relabeling: %.0f%% of each batch gets a goal achieved later in its episode%s\n", 100.0 * sc.her_share,
                sc.her_future_window > 0 ? (" (within " + std::to_string(sc.her_future_window) + " steps)").c_str() : "");
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  std::vector<float>& obs = m.obs;
  std::vector<float> next(od), act(ad);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  ReplayBatch<float> batch;
  SacStats sums;
  long long updates_in_row = 0, episodes_in_row = 0;
  double ret_sum = 0, len_sum = 0;
  SacRunResult result;
  if (m.opt.resume && m.opt.verbose) std::printf("resumed at env step %lld, update %lld\n", m.t_done, m.trainer->steps());
  const long long t_start = m.t_done;  // a resumed run's rate counts the steps of this process only
  for (long long t = m.t_done + 1; t <= sc.env_steps; ++t) {
    if (t <= sc.learning_starts) {
      for (float& a : act) a = uniform(m.rng);
    } else {
      m.trainer->explore(Eigen::Map<const Mat<float>>(obs.data(), od, 1), m.rng, Eigen::Map<Mat<float>>(act.data(), ad, 1));
    }
    const task::StepOutcome out = m.env->step(act.data());
    m.env->observe(next.data());
    m.replay.add(obs.data(), act.data(), out.reward, next.data(), out.terminated, out.truncated);
    if (out.terminated || out.truncated) {
      ret_sum += m.env->episode().ret;
      len_sum += m.env->episode().length;
      ++episodes_in_row;
      m.env->reset(m.rng);
      m.env->observe(obs.data());
    } else {
      obs = next;
    }
    m.t_done = t;
    if (t == sc.learning_starts) m.fitNormalizer();
    if (t >= sc.learning_starts) {
      // The steps this many transitions are owed (the schedule has no state of its own to resume).
      for (long long owed = gradientStepsOwed(sc, t - sc.learning_starts + 1); m.trainer->steps() < owed;) {
        m.hindsight->sample(m.replay, sc.batch_size, sc.n_step, sc.discount, m.rng, batch);
        const SacStats s = m.trainer->step(batch, m.rng);
        sums.q_loss += s.q_loss;
        sums.actor_loss += s.actor_loss;
        sums.alpha_loss += s.alpha_loss;
        sums.symmetry_loss += s.symmetry_loss;
        sums.alpha += s.alpha;
        sums.mean_q += s.mean_q;
        sums.entropy += s.entropy;
        ++updates_in_row;
      }
    }
    const bool eval_now = (sc.eval_every > 0 && t % sc.eval_every == 0) || t == sc.env_steps;
    if (t % sc.log_every != 0 && !eval_now) continue;
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    const double sps = (t - t_start) / std::max(wall, 1e-9);
    Impl::Eval e;
    if (eval_now) e = m.evaluate();
    const double nu = static_cast<double>(std::max<long long>(updates_in_row, 1));
    const double ne = static_cast<double>(episodes_in_row);
    std::ofstream& csv = m.files->metrics();
    csv << t << ',' << m.trainer->steps() << ',' << wall << ',' << sps << ','
          << (ne > 0 ? ret_sum / ne : std::nan("")) << ',' << (ne > 0 ? len_sum / ne : std::nan("")) << ','
          << episodes_in_row;
    for (double v : {sums.q_loss, sums.actor_loss, sums.alpha_loss, sums.symmetry_loss, sums.alpha, sums.mean_q, sums.entropy})
      csv << ',' << (updates_in_row > 0 ? v / nu : std::nan(""));
    if (eval_now) {
      csv << ',' << e.ret << ',' << e.length;
      for (double p : e.progress) csv << ',' << p;
    } else {
      csv << ",nan,nan";
      for (size_t i = 0; i < m.progress_names.size(); ++i) csv << ",nan";
    }
    csv << '\n';
    m.files->endRow();
    if (m.opt.verbose) {
      std::printf("env step %lld/%lld (%.0f%%)  %.0f steps/s  elapsed %s  ETA %s  updates %lld", t, sc.env_steps,
                  100.0 * t / sc.env_steps, sps, duration(wall).c_str(), duration((sc.env_steps - t) / sps).c_str(),
                  m.trainer->steps());
      if (ne > 0) std::printf("  return %.1f len %.0f (%lld ep)", ret_sum / ne, len_sum / ne, episodes_in_row);
      if (updates_in_row > 0)
        std::printf("  q_loss %.4g  alpha %.3g  entropy %.3g", sums.q_loss / nu, sums.alpha / nu, sums.entropy / nu);
      if (eval_now) std::printf("\n  eval (tanh(mean), %d episodes): return %.2f  len %.1f", sc.eval_episodes, e.ret, e.length);
      std::printf("\n");
      std::fflush(stdout);
    }
    if (eval_now) result.final_eval_return = e.ret;
    sums = SacStats{};
    updates_in_row = episodes_in_row = 0;
    ret_sum = len_sum = 0;
    if ((sc.checkpoint_every > 0 && t % sc.checkpoint_every == 0) || t == sc.env_steps) m.saveState();
  }
  result.env_steps = sc.env_steps;
  result.updates = m.trainer->steps();
  if (m.opt.verbose) std::printf("wrote %s/{config.yaml,metrics.csv,policy.bin,sac_state.bin}\n", m.opt.run_dir.c_str());
  return result;
}

}  // namespace masa::sac
