// The learner step of bench_learner_step.cpp in LibTorch, for comparison (issue #4): the same
// networks (Linear + ELU, float), the same losses written with tensor operations, autograd
// backward and torch::optim::Adam with the same hyper-parameters, at the same batch.
//
// LibTorch runs with whatever set-up the environment gives it (BLAS library, allocator
// settings); MASA_TORCH_THREADS, if set, is passed to torch::set_num_threads. The set-ups
// compared are in bench/run_learner_vs_libtorch.sh.
#include <benchmark/benchmark.h>
#include <torch/torch.h>

#include <chrono>
#include <cstdlib>

#include "../machine_peak.hpp"

namespace {

const bool kMachineDescribed = masa::bench::describeMachine();

constexpr int kObs = 74, kAct = 21;

torch::nn::Sequential mlp(int output) {
  return torch::nn::Sequential(torch::nn::Linear(kObs, 400), torch::nn::ELU(), torch::nn::Linear(400, 200),
                               torch::nn::ELU(), torch::nn::Linear(200, 100), torch::nn::ELU(),
                               torch::nn::Linear(100, output));
}

double flopsPerSample(int output) {
  const int w[] = {kObs, 400, 200, 100, output};
  double f = 0;
  for (int k = 0; k + 1 < 5; ++k) f += 6.0 * w[k] * w[k + 1];
  return f - 2.0 * w[0] * w[1];  // no input gradient for the first layer
}

void BM_LibTorchLearnerStep(benchmark::State& state, bool with_critic) {
  const int batch = static_cast<int>(state.range(0));
  if (const char* t = std::getenv("MASA_TORCH_THREADS")) torch::set_num_threads(std::atoi(t));
  torch::manual_seed(1);
  auto policy = mlp(kAct);
  auto critic = mlp(1);
  std::vector<torch::Tensor> params = policy->parameters();
  if (with_critic)
    for (const auto& p : critic->parameters()) params.push_back(p);
  torch::optim::Adam adam(params, torch::optim::AdamOptions(3e-4).betas({0.9, 0.999}).eps(1e-8));
  const auto obs = torch::rand({batch, kObs}) * 2 - 1;
  const auto actions = torch::rand({batch, kAct}) * 2 - 1;
  const auto returns = torch::rand({batch, 1}) * 2 - 1;
  const auto inv_var = torch::full({kAct}, 1.0 / (0.5 * 0.5));

  auto step = [&] {
    adam.zero_grad();
    auto loss = 0.5 * ((policy->forward(obs) - actions).pow(2) * inv_var).sum(1).mean();
    if (with_critic) loss = loss + 0.5 * (critic->forward(obs) - returns).pow(2).mean();
    loss.backward();
    adam.step();
  };
  step();  // first allocations stay out of the timing
  double seconds = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    step();
    benchmark::ClobberMemory();
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    state.SetIterationTime(dt);
    seconds += dt;
  }
  const double flops = flopsPerSample(kAct) + (with_critic ? flopsPerSample(1) : 0.0);
  const double gflops = flops * batch * static_cast<double>(state.iterations()) * 1e-9 / seconds;
  // This machine's measured peak for LibTorch's thread count, as bench_learner_step quotes it.
  const double peak = masa::bench::measuredPeakGflops(std::min(torch::get_num_threads(), 2));
  state.SetItemsProcessed(state.iterations() * batch);
  state.counters["GFLOPs"] = gflops;
  state.counters["of_peak"] = gflops / peak;
  state.counters["threads"] = torch::get_num_threads();
}

void args(benchmark::internal::Benchmark* b) {
  const char* env = std::getenv("MASA_BENCH_BATCH");
  b->ArgName("batch")->Arg(env ? std::atol(env) : 32768)->Unit(benchmark::kMillisecond)->UseManualTime();
}

BENCHMARK_CAPTURE(BM_LibTorchLearnerStep, Policy, false)->Apply(args);
BENCHMARK_CAPTURE(BM_LibTorchLearnerStep, ActorCritic, true)->Apply(args);

}  // namespace
