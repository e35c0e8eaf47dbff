// The learner's update with N data-parallel ranks (issue #30, docs/scaling.md): a plain program,
// run alone (one rank) or under mpirun, on a recipe's model and batch with synthetic samples.
//   bench/e2e_scaling.sh --ranks    (or: tests/mpi/mpirun.sh -np 2 build/bench/bench_learner_ranks --recipe a1_beam)
// Prints, on rank 0, one line: ranks, threads, the update's wall time (slowest rank; prepare and
// optimize), and per minibatch the gradient allreduce's floats, bytes and microseconds (mean over
// ranks), and what all the collectives together cost per update.
#include <CLI/CLI.hpp>
#include <omp.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <random>
#include <string>

#include "common/cluster/mpi_job.hpp"
#include "common/config/run_config.hpp"
#include "common/model/actor_critic.hpp"
#include "common/model/diag_gaussian.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "learner/ppo/ppo_trainer.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Counts and times what the trainer sums across ranks (the rest passes through).
class TimedCommunicator final : public masa::cluster::Communicator {
 public:
  explicit TimedCommunicator(masa::cluster::Communicator& inner) : inner_(inner) {}
  int rank() const override { return inner_.rank(); }
  int size() const override { return inner_.size(); }
  void sum(double* x, int n) override { timed([&] { inner_.sum(x, n); }, n * 8.0, false); }
  void sum(float* x, int n) override { timed([&] { inner_.sum(x, n); }, n * 4.0, true); }
  std::vector<int64_t> gather(int64_t x) override {
    std::vector<int64_t> out;
    timed([&] { out = inner_.gather(x); }, 8.0 * size(), false);
    return out;
  }
  void broadcast(std::vector<uint8_t>& b, int root) override { inner_.broadcast(b, root); }
  void beginBarrier() override { inner_.beginBarrier(); }
  bool barrierDone() override { return inner_.barrierDone(); }
  void reset() { calls = grad_calls = 0; seconds = grad_seconds = bytes = grad_bytes = 0; }

  long calls = 0, grad_calls = 0;
  double seconds = 0, grad_seconds = 0, bytes = 0, grad_bytes = 0;

 private:
  template <class F>
  void timed(F&& f, double b, bool gradient) {
    const auto t = Clock::now();
    f();
    const double s = since(t);
    ++calls;
    seconds += s;
    bytes += b;
    if (gradient) {
      ++grad_calls;
      grad_seconds += s;
      grad_bytes += b;
    }
  }
  masa::cluster::Communicator& inner_;
};

void fillBatch(masa::rollout::RolloutBuffer& b, masa::Rng& rng) {
  std::normal_distribution<float> n(0.f, 1.f);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  b.clear();
  b.obs() = masa::Mat<float>::NullaryExpr(b.obsDim(), b.size(), [&] { return n(rng); });
  b.bootstrapObs() = masa::Mat<float>::NullaryExpr(b.obsDim(), b.numEnvs(), [&] { return n(rng); });
  b.means() = masa::Mat<float>::NullaryExpr(b.actDim(), b.size(), [&] { return 0.3f * n(rng); });
  masa::Vec<float> log_std = masa::Vec<float>::Constant(b.actDim(), -0.5f);
  b.envLogStds().colwise() = log_std;
  masa::model::gaussian::sample<float>(b.means(), log_std, rng, b.actions());
  masa::model::gaussian::logProb<float>(b.means(), log_std, b.actions(), b.logProbs());
  b.terminated().setZero();
  b.truncated().setZero();
  for (int t = 0; t < b.horizon(); ++t)
    for (int e = 0; e < b.numEnvs(); ++e) {
      b.rewards()(t, e) = n(rng);
      b.terminated()(t, e) = u(rng) < 0.02f;
    }
}

}  // namespace

int main(int argc, char** argv) {
  std::unique_ptr<masa::cluster::MpiJob> job;
  if (masa::cluster::launchedByMpi()) job = std::make_unique<masa::cluster::MpiJob>(masa::cluster::Role::kLearner);
  CLI::App app{"the learner's update over data-parallel ranks (synthetic samples)"};
  std::string recipe = "a1_beam";
  int updates = 5;
  app.add_option("--recipe", recipe, "configs/recipes/NAME.yaml: the model and batch")->capture_default_str();
  app.add_option("--updates", updates, "timed updates (after one warm-up)")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  masa::cluster::Communicator& ranks = job ? job->learners() : masa::cluster::soloCommunicator();
  TimedCommunicator timed(ranks);

  const auto rc = masa::config::loadRunConfig(masa::config::defaultConfigsDir(), {"@" + recipe}, "");
  const auto spec = masa::sym::SymmetrySpec::load(rc.spec_path);
  masa::model::ModelConfig mc = rc.model;
  mc.method = rc.method;
  masa::model::ActorCritic<float> model(spec, mc);
  masa::Rng init(rc.seed);
  model.initialize(init);
  masa::nn::AdamConfig<float> ac;
  ac.lr = static_cast<float>(rc.ppo.learning_rate);
  masa::nn::Adam<float> adam(model.params(), ac);
  if (rc.rollout.num_envs % ranks.size() != 0) {
    std::fprintf(stderr, "num_envs %d does not divide among %d ranks\n", rc.rollout.num_envs, ranks.size());
    return 2;
  }
  masa::ppo::PpoTrainer trainer(model, adam, rc.ppo, timed);
  masa::rollout::RolloutBuffer buffer(rc.rollout.num_envs / ranks.size(), rc.rollout.horizon, model.obsDim(), model.actDim());
  masa::Rng data(1000 + ranks.rank()), shuffle(rc.seed);

  double prepare_s = 0, optimize_s = 0, wall_s = 0;
  int minibatches = 0;
  for (int u = 0; u <= updates; ++u) {
    fillBatch(buffer, data);
    if (u == 1) timed.reset();  // update 0 warms up (allocations, the MLP's chunk tuner)
    ranks.beginBarrier();  // start together: the wall time is the slowest rank's
    while (!ranks.barrierDone()) {
    }
    const auto t0 = Clock::now();
    trainer.prepare(buffer);
    const double p = since(t0);
    const auto t1 = Clock::now();
    const auto st = trainer.optimize(buffer, shuffle);
    const double o = since(t1);
    double times[3] = {p, o, since(t0)};
    if (u > 0) {
      // The slowest rank's times (max via -sum of -x is not available: gather the totals instead).
      for (double& x : times) {
        const auto all = ranks.gather(static_cast<int64_t>(x * 1e9));
        int64_t worst = 0;
        for (int64_t v : all) worst = std::max(worst, v);
        x = worst * 1e-9;
      }
      prepare_s += times[0];
      optimize_s += times[1];
      wall_s += times[2];
      minibatches += st.minibatches;
    }
  }
  if (ranks.rank() == 0) {
    const double per_mb_us = timed.grad_calls ? 1e6 * timed.grad_seconds / timed.grad_calls : 0.0;
    std::printf("%s ranks %d threads %d: update %.1f ms (prepare %.1f, optimize %.1f); %d samples/rank; per minibatch "
                "gradient allreduce %.0f floats (%.0f KB) in %.0f us; all collectives %.1f ms/update (%ld calls)\n",
                recipe.c_str(), ranks.size(), omp_get_max_threads(), 1e3 * wall_s / updates, 1e3 * prepare_s / updates,
                1e3 * optimize_s / updates, buffer.size(),
                timed.grad_calls ? timed.grad_bytes / 4 / timed.grad_calls : 0.0,
                timed.grad_calls ? timed.grad_bytes / 1024 / timed.grad_calls : 0.0, per_mb_us,
                1e3 * timed.seconds / updates, timed.calls / updates);
  }
  return 0;
}
