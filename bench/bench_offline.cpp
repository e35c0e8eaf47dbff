// Gradient steps per second of the offline learners (issue #11) against a PPO minibatch step of
// the same networks, on TriFinger Lift's spec (obs 41, act 9, C3) with the offline networks
// (policy, V and each Q: 256, 256, ELU, float), at batch 256 (BC's and IQL's) and 4096, for SA and
// MASA (MASA runs every network on its 3 agents: about 3x the work). One thread.
//   BC:   policy forward + Gaussian log-likelihood + backward + Adam (the critic is computed by the
//         model's forward and not trained)
//   IQL:  target min-Q, V step, actor step, Q step with V(o'), Polyak update (IqlTrainer::step)
//   PPO:  forward, clipped PPO loss, backward, grad-norm clip, Adam (PpoTrainer's minibatch step)
// Batches are drawn once; BM_SampleBatch times the draw of one batch from a 100k-transition dataset.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <filesystem>

#include "common/model/diag_gaussian.hpp"
#include "learner/offline/bc_trainer.hpp"
#include "learner/offline/iql_trainer.hpp"
#include "learner/offline/normalizer_fit.hpp"
#include "learner/ppo/ppo_loss.hpp"

namespace {

using namespace masa;

const sym::SymmetrySpec& spec() {
  static const sym::SymmetrySpec s =
      sym::SymmetrySpec::load((std::filesystem::path(MASA_SOURCE_DIR) / "configs/specs/trifinger_lift.yaml").string());
  return s;
}

model::ModelConfig offlineModel(model::Method method) {
  model::ModelConfig m;
  m.method = method;
  m.policy_hidden = {256, 256};
  m.critic_hidden = {256, 256};
  return m;
}

dataset::TransitionDataset randomData(int n) {
  Rng rng(1);
  std::normal_distribution<float> g;
  dataset::TransitionDataset d;
  d.task = "trifinger_lift";
  d.obs_dim = spec().obsDim();
  d.act_dim = spec().actDim();
  d.obs = Mat<float>::NullaryExpr(d.obs_dim, n, [&] { return g(rng); });
  d.next_obs = Mat<float>::NullaryExpr(d.obs_dim, n, [&] { return g(rng); });
  d.actions = Mat<float>::NullaryExpr(d.act_dim, n, [&] { return 0.5f * g(rng); });
  d.rewards = Vec<float>::NullaryExpr(n, [&] { return g(rng); });
  d.terminals.assign(n, 0);
  d.timeouts.assign(n, 0);
  d.policy_names = {"random"};
  d.episodes.push_back({0, 0, 0, n, 0.0, -1});
  return d;
}

const dataset::TransitionDataset& data() {
  static const dataset::TransitionDataset d = randomData(100000);
  return d;
}

model::Method methodOf(int64_t m) { return m == 0 ? model::Method::kSa : model::Method::kMasa; }

template <typename Step>
void timeSteps(benchmark::State& state, int batch, Step step) {
  step();  // first touch of every buffer stays out of the timing
  for (auto _ : state) step();
  state.SetItemsProcessed(state.iterations() * batch);
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_BcStep(benchmark::State& state) {
  omp_set_num_threads(1);
  const int batch = static_cast<int>(state.range(0));
  model::ActorCritic<float> m(spec(), offlineModel(methodOf(state.range(1))));
  Rng rng(2);
  m.initialize(rng);
  offline::fitObservationNormalizer(m, data());
  offline::BcTrainer<float> bc(m, offline::OfflineConfig{});
  offline::TransitionBatch<float> b;
  offline::sampleBatch(data(), batch, rng, b);
  timeSteps(state, batch, [&] { bc.step(b); });
}

void BM_IqlStep(benchmark::State& state) {
  omp_set_num_threads(1);
  const int batch = static_cast<int>(state.range(0));
  const model::Method method = methodOf(state.range(1));
  model::ActorCritic<float> m(spec(), offlineModel(method));
  offline::TwinQ<float> q(spec(), method, {256, 256}, nn::Activation::kElu);
  offline::TwinQ<float> q_target(spec(), method, {256, 256}, nn::Activation::kElu);
  Rng rng(3);
  m.initialize(rng);
  q.initialize(rng);
  q_target.moveTowards(q, 1.0f);
  offline::fitObservationNormalizer(m, data());
  offline::IqlTrainer<float> iql(m, q, q_target, offline::OfflineConfig{});
  offline::TransitionBatch<float> b;
  offline::sampleBatch(data(), batch, rng, b);
  timeSteps(state, batch, [&] { iql.step(b); });
}

void BM_PpoStep(benchmark::State& state) {
  omp_set_num_threads(1);
  const int batch = static_cast<int>(state.range(0));
  model::ActorCritic<float> m(spec(), offlineModel(methodOf(state.range(1))));
  Rng rng(4);
  m.initialize(rng);
  offline::fitObservationNormalizer(m, data());
  nn::Adam<float> adam(m.params());
  const int a = spec().actDim();
  ppo::PpoLoss<float> loss(ppo::PpoLossConfig{}, a, batch);
  offline::TransitionBatch<float> b;
  offline::sampleBatch(data(), batch, rng, b);
  Vec<float> log_std(a);
  m.forward(b.obs);
  m.logStd(log_std);
  const Mat<float> old_mean = m.mean(), old_value = m.value(), old_log_std = log_std;
  Mat<float> old_logp(1, batch);
  model::gaussian::logProb<float>(old_mean, log_std, b.actions, old_logp);
  const Mat<float> adv = b.rewards, returns = b.rewards;
  timeSteps(state, batch, [&] {
    m.forward(b.obs);
    m.logStd(log_std);
    loss.compute({m.mean(), log_std, m.value(), b.actions, old_logp, old_mean, old_log_std, adv, old_value, returns});
    m.params().zeroGrad();
    m.backward(loss.dmean(), loss.dlogStd(), loss.dvalue());
    nn::clipGradNorm(m.params(), 1.0f);
    adam.step();
  });
}

void BM_SampleBatch(benchmark::State& state) {
  const int batch = static_cast<int>(state.range(0));
  Rng rng(5);
  offline::TransitionBatch<float> b;
  timeSteps(state, batch, [&] { offline::sampleBatch(data(), batch, rng, b); });
}

void args(benchmark::internal::Benchmark* b) {
  b->ArgNames({"batch", "masa"});
  for (int batch : {256, 4096})
    for (int masa : {0, 1}) b->Args({batch, masa});
  b->Unit(benchmark::kMicrosecond);
}

BENCHMARK(BM_BcStep)->Apply(args);
BENCHMARK(BM_IqlStep)->Apply(args);
BENCHMARK(BM_PpoStep)->Apply(args);
BENCHMARK(BM_SampleBatch)->Arg(256)->Arg(4096)->Unit(benchmark::kMicrosecond);

}  // namespace
