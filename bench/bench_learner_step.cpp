// One learner minibatch step of the humanoid-sized networks (issue #4): forward, loss gradient,
// backward and Adam, at B = 32768 by default, on 1 and 2 threads. bench/libtorch/ times the same
// step in LibTorch; bench/run_learner_vs_libtorch.sh runs both interleaved.
//
// Networks, ELU, float: policy 74 -> 400 -> 200 -> 100 -> 21; critic 74 -> 400 -> 200 -> 100 -> 1.
// "Policy" is the policy alone (731,000 FLOP a sample, the 24 GFLOP of the issue); "ActorCritic"
// is both networks in one parameter set under one Adam, as the PPO trainer has them (1,450,000).
// Losses: a Gaussian log-likelihood of actions under the policy mean with a fixed std, and a
// squared value error; their gradients are elementwise and counted as free. FLOPs count the
// products exactly: 2*in*out per layer forward, 4*in*out backward less the first layer's dx.
//
// Counters: GFLOPs (GFLOP/s over the timed steps), and of_peak = that over this machine's fp32 FMA
// peak for the threads used, measured at start-up (machine_peak.hpp; the CPU model and the peaks
// are in the benchmark's context lines).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <chrono>
#include <cstdlib>
#include <memory>
#include <vector>

#include "common/nn/adam.hpp"
#include "common/nn/mlp.hpp"
#include "machine_peak.hpp"
#include "mlp_flops.hpp"

namespace {

using masa::Mat;
using masa::nn::Adam;
using masa::nn::Mlp;
using masa::nn::MlpShape;
using masa::nn::ParameterSet;

constexpr int kObs = masa::bench::kHumanoidObs, kAct = masa::bench::kHumanoidAct;

MlpShape shape(int output) { return masa::bench::humanoidNetwork(output); }

const bool kMachineDescribed = masa::bench::describeMachine();

double peakGflops(int threads) { return masa::bench::measuredPeakGflops(threads); }

// Policy, and optionally critic, with their batch, targets and optimizer.
struct Learner {
  ParameterSet<float> params;
  std::unique_ptr<Mlp<float>> policy, critic;
  std::unique_ptr<Adam<float>> adam;
  Mat<float> obs, actions, returns, dmean, dvalue;
  Eigen::VectorXf inv_var;

  Learner(int batch, bool with_critic) {
    policy = std::make_unique<Mlp<float>>(params, "policy", shape(kAct));
    if (with_critic) critic = std::make_unique<Mlp<float>>(params, "critic", shape(1));
    params.finalize();
    masa::Rng rng(1);
    policy->initialize(rng, 0.01f);
    if (critic) critic->initialize(rng);
    adam = std::make_unique<Adam<float>>(params);
    obs = Mat<float>::Random(kObs, batch);
    actions = Mat<float>::Random(kAct, batch);
    returns = Mat<float>::Random(1, batch);
    dmean.resize(kAct, batch);
    dvalue.resize(1, batch);
    inv_var = Eigen::VectorXf::Constant(kAct, 1.f / (0.5f * 0.5f));
  }

  void step() {
    const float inv_b = 1.f / static_cast<float>(obs.cols());
    params.zeroGrad();
    // loss = mean_b 0.5 sum_i (a_i - mu_i)^2 / sigma_i^2  (+ mean_b 0.5 (V - R)^2)
    const auto mean = policy->forward(obs);
    dmean.array() = (mean - actions).array().colwise() * (inv_var.array() * inv_b);
    policy->backward(dmean);
    if (critic) {
      const auto value = critic->forward(obs);
      dvalue.array() = (value - returns).array() * inv_b;
      critic->backward(dvalue);
    }
    adam->step();
  }
};

void BM_LearnerStep(benchmark::State& state, bool with_critic) {
  const int batch = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const int saved_threads = omp_get_max_threads();
  omp_set_num_threads(threads);  // before the networks size their per-thread buffers
  {
    Learner learner(batch, with_critic);
    // MASA_BENCH_CHUNK forces the fused engine's chunk width; otherwise the warm-up runs until
    // both networks have measured theirs (chunk_tuner.hpp), so the timing sees the chosen width.
    if (const char* chunk = std::getenv("MASA_BENCH_CHUNK")) {
      learner.policy->forceChunkWidth(std::atoi(chunk));
      if (learner.critic) learner.critic->forceChunkWidth(std::atoi(chunk));
    }
    learner.step();  // first touch of every buffer stays out of the timing
    for (int warm_up = 0; warm_up < 20 && !(learner.policy->chunkTuner().settled() &&
                                            (!learner.critic || learner.critic->chunkTuner().settled()));
         ++warm_up)
      learner.step();
    double seconds = 0;
    for (auto _ : state) {
      const auto start = std::chrono::steady_clock::now();
      learner.step();
      benchmark::DoNotOptimize(learner.params.values().data());
      benchmark::ClobberMemory();
      const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      state.SetIterationTime(dt);
      seconds += dt;
    }
    double flops = masa::bench::trainingFlopsPerSample(shape(kAct));
    if (with_critic) flops += masa::bench::trainingFlopsPerSample(shape(1));
    const double gflops = flops * batch * static_cast<double>(state.iterations()) * 1e-9 / seconds;
    state.SetItemsProcessed(state.iterations() * batch);
    state.counters["GFLOPs"] = gflops;
    state.counters["of_peak"] = gflops / peakGflops(threads);
    state.SetLabel("chunk " + learner.policy->chunkTuner().summary());
  }
  omp_set_num_threads(saved_threads);
}

void args(benchmark::internal::Benchmark* b) {
  const char* env = std::getenv("MASA_BENCH_BATCH");
  const long batch = env ? std::atol(env) : 32768;
  b->ArgNames({"batch", "threads"})->Args({batch, 1})->Args({batch, 2});
  b->Unit(benchmark::kMillisecond)->UseManualTime();
}

BENCHMARK_CAPTURE(BM_LearnerStep, Policy, false)->Apply(args);
BENCHMARK_CAPTURE(BM_LearnerStep, ActorCritic, true)->Apply(args);

}  // namespace
