// The actor's collection loop against bare MuJoCo on one core (issue #4: the actor must keep at
// least 0.9 of raw mj_step throughput of the same model and frame skip).
//
//   RawPhysics/<task>: E mjData of the task's model, each env step = frame_skip x (copy the
//     recorded ctrl, mj_step), and the recorded resets (mj_resetData, state copy, mj_forward).
//     No task code runs: this is what MuJoCo alone costs along the recorded trajectory (bit for
//     bit, counter exact = 1, where the task renormalizes quaternions once per step).
//   TaskStep/<task>:   E tasks, Task::step + observe on the recorded actions, resets as recorded
//     (the same trajectory as RawPhysics, bit for bit: the setup checks it).
//   Actor/<task>:      masa::actor::Actor over an in-process memq:// LCM with its own initial
//     parameters: policy inference, Gaussian sampling, Task::step, rollout recording, chunking
//     and publishing. One iteration is one rollout of E x T env steps.
//
// The recording acts with N(0, 1) actions, the law of the actor's untrained policy (mean about 0
// from the scaled last layer, log std 0), so Actor's own trajectories follow the same law; the
// per-substep ctrl (the tasks' PD loops rewrite it every substep) is captured with mjcb_control.
// Each environment replays a sequence of its own, so that the physics cost is averaged over as
// many episodes as the actor's 32 environments see (the resets_per_1k counters compare them).
// Compare items_per_second (env steps/s); run on one pinned core with interleaved repetitions:
//   OMP_NUM_THREADS=1 taskset -c 1 build/bench/bench_actor --benchmark_repetitions=8
//       --benchmark_enable_random_interleaving=true --benchmark_min_time=0.5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstring>
#include <map>
#include <random>

#include "actors/actor.hpp"
#include "common/config/run_config.hpp"
#include "common/sim/registry.hpp"
#include "common/transport/transport.hpp"
#include "tasks/tasks.hpp"

namespace {

using namespace masa;

constexpr int kSteps = 1024;  // env steps recorded per environment
constexpr int kEnvs = 32;     // deploy/train.sh's environments per actor
constexpr int kCheck = kSteps - 2;

config::RunConfig runConfig(const std::string& name) {
  return config::loadRunConfig(config::defaultConfigsDir(), {"task=" + name});
}

// One environment's recorded sequence.
struct Sequence {
  std::vector<float> actions;        // kSteps x act_dim
  std::vector<double> ctrl;          // kSteps x frame_skip x nu, as mj_step used it
  std::vector<char> done;            // the episode ended at this step: reset right after it
  std::vector<double> reset_states;  // (qpos, qvel, act) after each reset, the first one included
  std::vector<Rng> reset_rngs;       // the generator before each reset, to redo it in a Task
  std::vector<double> check_qpos;    // after step kCheck: the replays must reach it
};

struct Recording {
  std::unique_ptr<task::TaskFactory> factory;
  int frame_skip = 0;
  std::vector<Sequence> seqs;  // one per environment
  bool raw_exact = false, task_exact = false;
  double resets_per_1k = 0;    // episode ends per 1000 env steps over all sequences
};

// mjcb_control is global and fires inside every mj_forward (mj_step runs one per Euler substep),
// with d->ctrl exactly as actuation will read it.
std::vector<double>* g_ctrl_sink = nullptr;
int g_callback_calls = 0;
void recordCtrl(const mjModel* m, mjData* d) {
  if (!g_ctrl_sink) return;
  ++g_callback_calls;
  g_ctrl_sink->insert(g_ctrl_sink->end(), d->ctrl, d->ctrl + m->nu);
}

std::size_t stateSize(const mjModel* m) { return static_cast<std::size_t>(m->nq + m->nv + m->na); }

void saveState(const mjModel* m, const mjData* d, std::vector<double>& out) {
  out.insert(out.end(), d->qpos, d->qpos + m->nq);
  out.insert(out.end(), d->qvel, d->qvel + m->nv);
  out.insert(out.end(), d->act, d->act + m->na);
}

// What Task::reset does to the simulator, minus the task's own sampling.
void loadState(const mjModel* m, mjData* d, const double* s) {
  mj_resetData(m, d);
  std::memcpy(d->qpos, s, sizeof(double) * m->nq);
  std::memcpy(d->qvel, s + m->nq, sizeof(double) * m->nv);
  std::memcpy(d->act, s + m->nq + m->nv, sizeof(double) * m->na);
  mj_forward(m, d);
}

// E bare mjData stepped in lockstep, environment e along sequence e, env after env as the actor
// steps them.
class RawEnvs {
 public:
  RawEnvs(const Recording& r, int num_envs) : r_(r), m_(r.factory->model()->get()) {
    for (int e = 0; e < num_envs; ++e) d_.push_back(mj_makeData(m_));
    reset_.assign(num_envs, 0);
    restart();
  }
  ~RawEnvs() {
    for (mjData* d : d_) mj_deleteData(d);
  }
  RawEnvs(const RawEnvs&) = delete;
  RawEnvs& operator=(const RawEnvs&) = delete;

  void step() {
    const std::size_t nu = m_->nu;
    for (std::size_t e = 0; e < d_.size(); ++e) {
      const Sequence& q = r_.seqs[e];
      mjData* d = d_[e];
      const double* c = q.ctrl.data() + static_cast<std::size_t>(k_) * r_.frame_skip * nu;
      for (int s = 0; s < r_.frame_skip; ++s) {
        std::memcpy(d->ctrl, c + s * nu, sizeof(double) * nu);
        mj_step(m_, d);
      }
      // The task's pose refresh (mj_kinematics) renormalizes the quaternions of qpos in place;
      // without it the next substep would see them 1 ulp apart and the trajectory would drift.
      mj_normalizeQuat(m_, d->qpos);
      if (q.done[k_]) loadState(m_, d, q.reset_states.data() + ++reset_[e] * stateSize(m_));
    }
    if (++k_ == kSteps) restart();
  }
  const mjData* data(int e) const { return d_[e]; }

 private:
  void restart() {
    k_ = 0;
    for (std::size_t e = 0; e < d_.size(); ++e) {
      reset_[e] = 0;
      loadState(m_, d_[e], r_.seqs[e].reset_states.data());
    }
  }
  const Recording& r_;
  const mjModel* m_;
  std::vector<mjData*> d_;
  std::vector<std::size_t> reset_;  // per environment: resets done in its sequence
  int k_ = 0;
};

// E tasks stepped in lockstep along their sequences: Task::step + observe, resets redone from
// the recorded generator states.
class TaskEnvs {
 public:
  TaskEnvs(const Recording& r, int num_envs) : r_(r) {
    for (int e = 0; e < num_envs; ++e) envs_.push_back(r.factory->create());
    obs_.resize(envs_[0]->obsDim());
    reset_.assign(num_envs, 0);
    restart();
  }
  void step() {
    const std::size_t A = envs_[0]->actDim();
    for (std::size_t e = 0; e < envs_.size(); ++e) {
      const Sequence& q = r_.seqs[e];
      envs_[e]->step(q.actions.data() + k_ * A);
      if (q.done[k_]) reset(e, ++reset_[e]);
      envs_[e]->observe(obs_.data());
      benchmark::DoNotOptimize(obs_.data());
    }
    if (++k_ == kSteps) restart();
  }
  const task::Task& env(int e) const { return *envs_[e]; }

 private:
  void reset(std::size_t e, std::size_t i) {
    Rng g = r_.seqs[e].reset_rngs[i];
    envs_[e]->reset(g);
  }
  void restart() {
    k_ = 0;
    for (std::size_t e = 0; e < envs_.size(); ++e) reset(e, reset_[e] = 0);
  }
  const Recording& r_;
  std::vector<std::unique_ptr<task::Task>> envs_;
  std::vector<float> obs_;
  std::vector<std::size_t> reset_;
  std::size_t k_ = 0;
};

bool sameQpos(const mjData* d, const std::vector<double>& q) {
  return std::memcmp(d->qpos, q.data(), sizeof(double) * q.size()) == 0;
}

// Steps one task for kSteps with N(0, 1) actions from its own seeds, recording everything the
// replays need.
Sequence recordSequence(task::Task& env, int frame_skip, std::uint64_t seed) {
  const mjModel* m = env.model();
  const int A = env.actDim();
  Sequence q;
  Rng act_rng(2 * seed + 1), reset_rng(2 * seed);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  q.actions.resize(static_cast<std::size_t>(kSteps) * A);
  for (float& a : q.actions) a = gauss(act_rng);
  q.done.resize(kSteps);
  auto reset = [&] {
    q.reset_rngs.push_back(reset_rng);
    env.reset(reset_rng);
    saveState(m, env.data(), q.reset_states);
  };
  reset();
  // Task::step runs mj_kinematics and mj_comPos after its substeps but no mj_forward, so the
  // callback fires in the substeps alone; resets (which run mj_forward) happen with it disarmed.
  std::vector<double> step_ctrl;
  for (int k = 0; k < kSteps; ++k) {
    step_ctrl.clear();
    g_ctrl_sink = &step_ctrl;
    g_callback_calls = 0;
    const auto out = env.step(q.actions.data() + static_cast<std::size_t>(k) * A);
    g_ctrl_sink = nullptr;
    // One call per substep with Euler; an integrator with more stages calls it more often, with
    // the same ctrl: keep the first of each substep.
    const int per_substep = g_callback_calls / frame_skip;
    for (int s = 0; s < frame_skip; ++s) {
      const double* c = step_ctrl.data() + static_cast<std::size_t>(s) * per_substep * m->nu;
      q.ctrl.insert(q.ctrl.end(), c, c + m->nu);
    }
    q.done[k] = out.terminated || out.truncated;
    if (q.done[k]) reset();
    if (k == kCheck) q.check_qpos.assign(env.data()->qpos, env.data()->qpos + m->nq);
  }
  return q;
}

const Recording& recording(const std::string& name) {
  static std::map<std::string, Recording> cache;  // repetitions re-enter: record once per task
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  Recording& r = cache[name];
  const auto rc = runConfig(name);
  r.factory = std::make_unique<task::TaskFactory>(task::taskCatalog(), rc.task, sym::SymmetrySpec::load(rc.spec_path), rc.env, rc.origin);
  auto env = r.factory->create();
  r.frame_skip = static_cast<int>(std::lround(env->controlTimestep() / env->model()->opt.timestep));
  mjcb_control = recordCtrl;
  int ends = 0;
  for (int e = 0; e < kEnvs; ++e) {
    r.seqs.push_back(recordSequence(*env, r.frame_skip, static_cast<std::uint64_t>(e)));
    for (char d : r.seqs.back().done) ends += d;
  }
  mjcb_control = nullptr;
  r.resets_per_1k = 1000.0 * ends / (static_cast<double>(kSteps) * kEnvs);

  // Both replays of sequence 0 must reach the recorded state: bit for bit the same trajectory.
  RawEnvs raw(r, 1);
  TaskEnvs tasks(r, 1);
  for (int k = 0; k <= kCheck; ++k) {
    raw.step();
    tasks.step();
  }
  r.raw_exact = sameQpos(raw.data(0), r.seqs[0].check_qpos);
  r.task_exact = sameQpos(tasks.env(0).data(), r.seqs[0].check_qpos);
  return r;
}

void setCounters(benchmark::State& state, const Recording& r, int64_t env_steps) {
  state.SetItemsProcessed(env_steps);
  state.counters["frame_skip"] = r.frame_skip;
  state.counters["envs"] = kEnvs;
}

void rawPhysics(benchmark::State& state, const std::string& name) {
  const Recording& r = recording(name);
  RawEnvs envs(r, kEnvs);
  for (auto _ : state) envs.step();
  setCounters(state, r, state.iterations() * kEnvs);
  // 1: bit for bit on the recorded trajectory. 0 where the task renormalizes quaternions more
  // than once per step (trifinger_lift's afterStep): 1 ulp apart, the same law of trajectories.
  state.counters["exact"] = r.raw_exact;
  state.counters["resets_per_1k"] = r.resets_per_1k;
}

void taskStep(benchmark::State& state, const std::string& name) {
  const Recording& r = recording(name);
  if (!r.task_exact) state.SkipWithError("the task replay left the recorded trajectory");
  TaskEnvs envs(r, kEnvs);
  for (auto _ : state) envs.step();
  setCounters(state, r, state.iterations() * kEnvs);
  state.counters["exact"] = r.task_exact;
  state.counters["resets_per_1k"] = r.resets_per_1k;
}

void actorLoop(benchmark::State& state, const std::string& name) {
  const Recording& r = recording(name);
  const auto rc = runConfig(name);
  transport::Transport bus("memq://");
  actor::ActorOptions opt;
  opt.num_envs = kEnvs;
  opt.threads = 1;
  opt.start_without_learner = true;
  actor::Actor actor(rc, opt, &bus);
  actor.collectAndPublish();  // first touch of the rollout and the network's buffers
  int64_t episodes = 0;
  for (auto _ : state) {
    actor.collectAndPublish();
    episodes += actor.lastRollout().numEpisodes();
  }
  const int64_t steps = state.iterations() * kEnvs * rc.rollout.horizon;
  setCounters(state, r, steps);
  state.counters["horizon"] = rc.rollout.horizon;
  state.counters["resets_per_1k"] = 1000.0 * static_cast<double>(episodes) / static_cast<double>(steps);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  for (const std::string& name : masa::task::taskCatalog().names()) {
    if (name == "mjcf") continue;
    benchmark::RegisterBenchmark(("RawPhysics/" + name).c_str(), rawPhysics, name);
    benchmark::RegisterBenchmark(("TaskStep/" + name).c_str(), taskStep, name);
    benchmark::RegisterBenchmark(("Actor/" + name).c_str(), actorLoop, name);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
