// Learner and actor cost of the humanoid-sized policy (74 -> 400 -> 200 -> 100 -> 21, ELU) in float.
// FLOPs count the products exactly: 2*in*out per layer forward, 4*in*out backward (dW and dx), less
// the first layer's dx, which training does not compute; elementwise work is not counted.
#include <benchmark/benchmark.h>


#include "common/nn/adam.hpp"
#include "common/nn/dense_kernels.hpp"
#include "common/nn/mlp.hpp"
#include "machine_peak.hpp"
#include "mlp_flops.hpp"

namespace {

using masa::Mat;
using masa::MatRef;
using masa::nn::Adam;
using masa::nn::Mlp;
using masa::nn::MlpShape;
using masa::nn::ParameterSet;

MlpShape humanoidPolicy() {
  MlpShape s;
  s.input = 74;
  s.hidden = {400, 200, 100};
  s.output = 21;
  s.hidden_activation = masa::nn::Activation::kElu;
  return s;
}

const bool kMachineDescribed = masa::bench::describeMachine();

// GFLOP/s; this machine's measured peak is in the context lines (fp32_fma_peak_gflops_*).
void report(benchmark::State& state, int batch, double flops_per_sample) {
  state.SetItemsProcessed(state.iterations() * batch);
  const double gflop = flops_per_sample * batch * static_cast<double>(state.iterations()) * 1e-9;
  state.counters["GFLOP/s"] = benchmark::Counter(gflop, benchmark::Counter::kIsRate);
}

void BM_TrainStep(benchmark::State& state) {
  const int B = static_cast<int>(state.range(0));
  const MlpShape shape = humanoidPolicy();
  ParameterSet<float> params;
  Mlp<float> mlp(params, "policy", shape);
  params.finalize();
  masa::Rng rng(1);
  mlp.initialize(rng);
  Adam<float> adam(params);
  const Mat<float> x = Mat<float>::Random(shape.input, B);
  const Mat<float> dy = Mat<float>::Random(shape.output, B) * 1e-3f;
  mlp.forward(x);  // first touch of the buffers stays out of the timing
  mlp.backward(dy);
  for (auto _ : state) {
    params.zeroGrad();
    benchmark::DoNotOptimize(mlp.forward(x).data());
    mlp.backward(dy);
    adam.step();
    benchmark::ClobberMemory();
  }
  report(state, B, masa::bench::trainingFlopsPerSample(shape));  // 731,000 here
}
BENCHMARK(BM_TrainStep)->Arg(1)->Arg(16)->Arg(4096)->Arg(32768)->Unit(benchmark::kMicrosecond)->UseRealTime();

void inferOn(benchmark::State& state, bool frozen) {
  const int B = static_cast<int>(state.range(0));
  const MlpShape shape = humanoidPolicy();
  ParameterSet<float> params;
  Mlp<float> mlp(params, "policy", shape);
  params.finalize();
  masa::Rng rng(1);
  mlp.initialize(rng);
  if (frozen) params.freeze();
  const Mat<float> x = Mat<float>::Random(shape.input, B);
  mlp.infer(x);
  for (auto _ : state) benchmark::DoNotOptimize(mlp.infer(x).data());
  report(state, B, masa::bench::forwardFlopsPerSample(shape));
  // Inference runs on one thread at these sizes: of_peak is the share of one core's FMA peak, and
  // its inverse how far the time is from the FLOP bound.
  const double gflops = masa::bench::forwardFlopsPerSample(shape) * B * static_cast<double>(state.iterations()) * 1e-9;
  state.counters["of_peak"] =
      benchmark::Counter(gflops / masa::bench::measuredPeakGflops(1), benchmark::Counter::kIsRate);
}
void BM_Infer(benchmark::State& state) { inferOn(state, false); }
// Frozen parameters (the robot runner): 1-4 columns read W packed for their column count.
void BM_InferFrozen(benchmark::State& state) { inferOn(state, true); }
// 1: one agent (SA) in the robot runner; 2 and 4: a robot's agents (MASA: N columns a step); 16: a
// small batch of environments.
BENCHMARK(BM_Infer)->Arg(1)->Arg(2)->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_InferFrozen)->Arg(1)->Arg(2)->Arg(3)->Arg(4)->Unit(benchmark::kMicrosecond)->UseRealTime();

// One dense layer's forward over 1-4 columns (depth 400, ELU), rows 200 (a masked last vector,
// columns starting mid cache line) and 400 (two row blocks at 2 columns), on W in place or packed
// for the column count (dense::packForward): ns per weight, i.e. how fast W streams from L2
// (docs/benchmarks.md, issue #14).
void BM_NarrowForward(benchmark::State& state) {
  if (!masa::nn::dense::kAvailable) return state.SkipWithError("built without AVX-512");
  const int rows = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1)), depth = 400;
  const bool packed = state.range(2) != 0;
  const Mat<float> w = Mat<float>::Random(rows, depth) * 0.05f;
  const Mat<float> x = Mat<float>::Random(depth, n), b = Mat<float>::Random(rows, 1);
  masa::Vec<float> pack(masa::nn::dense::packedSize(rows, depth));  // 64-byte aligned, as Mlp's packs
  masa::nn::dense::packForward(w.data(), rows, rows, depth, n, pack.data());
  Mat<float> y(rows, n);
  for (auto _ : state) {
    if (packed)
      masa::nn::dense::forwardPacked(pack.data(), rows, depth, b.data(), masa::nn::Activation::kElu, x.data(), depth,
                                     y.data(), rows, n);
    else
      masa::nn::dense::forward(w.data(), rows, rows, depth, b.data(), masa::nn::Activation::kElu, x.data(), depth,
                               y.data(), rows, n);
    benchmark::DoNotOptimize(y.data());
  }
  state.counters["ns_per_weight"] = benchmark::Counter(static_cast<double>(rows) * depth * 1e-9,
                                                       benchmark::Counter::kIsIterationInvariantRate |
                                                           benchmark::Counter::kInvert);
}
BENCHMARK(BM_NarrowForward)->ArgNames({"rows", "columns", "packed"})->ArgsProduct({{200, 208, 400}, {1, 2, 3, 4}, {0, 1}})
    ->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace
