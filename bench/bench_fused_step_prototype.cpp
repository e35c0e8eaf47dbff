// Issue #14, an experiment, not the trainer's path: how much of the two-thread gap at B = 32768
// would a learner step recover that takes each chunk of columns through forward, loss gradient and
// backward back to back, so that its activations never leave L2 (Mlp keeps every layer's
// activations of the whole batch for backward: 97 MB at 32768, through DRAM)?
//
// "Current" is bench_learner_step's Policy step (Mlp forward, loss gradient, Mlp backward, Adam).
// "ChunkFused" is the same network, loss and FLOPs on the same dense kernels, with per-thread
// chunk buffers: forward 74 -> 400 -> 200 -> 100 -> 21, dy = (y - a) / sigma^2 / B, backward with
// weight gradients into per-thread partials, summed, then Adam. The sums differ in order from
// Current's, so it is not bit-identical to it; it measures speed only.
//   MASA_BENCH_BATCH=32768 build/bench/bench_fused_step_prototype --benchmark_repetitions=3
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "common/nn/adam.hpp"
#include "common/nn/dense_kernels.hpp"
#include "common/nn/mlp.hpp"
#include "machine_peak.hpp"
#include "mlp_flops.hpp"

namespace {

using masa::Mat;
using masa::Vec;
using masa::nn::Activation;
using masa::nn::Adam;
using masa::nn::Mlp;
using masa::nn::MlpShape;
using masa::nn::ParameterSet;
namespace dense = masa::nn::dense;

constexpr int kObs = masa::bench::kHumanoidObs, kAct = masa::bench::kHumanoidAct;
constexpr std::array<int, 5> kWidth{kObs, 400, 200, 100, kAct};  // the layers of kShape
constexpr int kLayers = 4;
const MlpShape kShape = masa::bench::humanoidNetwork(kAct);

const bool kMachineDescribed = masa::bench::describeMachine();

int padded(int rows) { return (rows + 15) / 16 * 16; }

struct Batch {
  Mat<float> obs, actions;
  Eigen::VectorXf inv_var;
  explicit Batch(int b) : obs(Mat<float>::Random(kObs, b)), actions(Mat<float>::Random(kAct, b)) {
    inv_var = Eigen::VectorXf::Constant(kAct, 1.f / (0.5f * 0.5f));
  }
};

// The Mlp path, as bench_learner_step's Policy.
struct Current {
  ParameterSet<float> params;
  std::unique_ptr<Mlp<float>> policy;
  std::unique_ptr<Adam<float>> adam;
  Batch batch;
  Mat<float> dmean;
  explicit Current(int b) : batch(b), dmean(kAct, b) {
    policy = std::make_unique<Mlp<float>>(params, "policy", kShape);
    params.finalize();
    masa::Rng rng(1);
    policy->initialize(rng);
    adam = std::make_unique<Adam<float>>(params);
  }
  void step() {
    const float inv_b = 1.f / static_cast<float>(batch.obs.cols());
    params.zeroGrad();
    const auto mean = policy->forward(batch.obs);
    dmean.array() = (mean - batch.actions).array().colwise() * (batch.inv_var.array() * inv_b);
    policy->backward(dmean);
    adam->step();
  }
};

// Chunks through forward, loss gradient and backward on per-thread buffers.
struct ChunkFused {
  static constexpr int kChunk = 256;
  ParameterSet<float> params;
  std::array<int, kLayers> w_offset{}, b_offset{};
  std::unique_ptr<Adam<float>> adam;
  Batch batch;
  Vec<float> packed_t;
  std::array<Eigen::Index, kLayers> packed_offset{};
  struct Scratch {
    std::array<Mat<float>, kLayers> a;  // post-activations of the chunk, rows padded
    Mat<float> d0, d1;                  // alternating input gradients
    Vec<float> grad;                    // this thread's gradient partial
  };
  std::vector<Scratch> scratch;

  explicit ChunkFused(int b) : batch(b) {
    for (int k = 0; k < kLayers; ++k) {
      w_offset[k] = params.reserve("w" + std::to_string(k), kWidth[k + 1], kWidth[k]);
      b_offset[k] = params.reserve("b" + std::to_string(k), kWidth[k + 1], 1);
    }
    params.finalize();
    params.values().setRandom();
    params.values() *= 0.05f;
    adam = std::make_unique<Adam<float>>(params);
    Eigen::Index size = 0;
    for (int k = 0; k < kLayers; ++k) {
      packed_offset[k] = size;
      size += dense::packedSize(kWidth[k], kWidth[k + 1]);
    }
    packed_t.setZero(size);
    scratch.resize(std::max(1, omp_get_max_threads()));
    for (Scratch& s : scratch) {
      for (int k = 0; k < kLayers; ++k) s.a[k].setZero(padded(kWidth[k + 1]), kChunk);
      s.d0.setZero(padded(400), kChunk);
      s.d1.setZero(padded(400), kChunk);
      s.grad.setZero(params.size());
    }
  }

  void chunk(Scratch& s, int j0, int n, float inv_b) {
    const float* values = std::as_const(params).values().data();
    const float* x = batch.obs.data() + static_cast<Eigen::Index>(j0) * kObs;
    const float* in = x;
    Eigen::Index ld_in = kObs;
    for (int k = 0; k < kLayers; ++k) {
      const Activation act = k + 1 == kLayers ? Activation::kIdentity : Activation::kElu;
      dense::forward(values + w_offset[k], kWidth[k + 1], kWidth[k + 1], kWidth[k], values + b_offset[k], act, in,
                     ld_in, s.a[k].data(), s.a[k].rows(), n);
      in = s.a[k].data();
      ld_in = s.a[k].rows();
    }
    // dy = (y - a) / sigma^2 / B into d0.
    const Eigen::Index ld_d = s.d0.rows();
    for (int j = 0; j < n; ++j)
      for (int r = 0; r < kAct; ++r)
        s.d0(r, j) = (s.a[kLayers - 1](r, j) - batch.actions(r, j0 + j)) * batch.inv_var(r) * inv_b;
    const float* g = s.d0.data();
    Mat<float>* free_buffer = &s.d1;
    float* grad = s.grad.data();
    for (int k = kLayers - 1; k >= 0; --k) {
      const float* xk = k == 0 ? x : s.a[k - 1].data();
      const Eigen::Index ld_x = k == 0 ? kObs : s.a[k - 1].rows();
      dense::weightGrad(kWidth[k + 1], kWidth[k], n, g, ld_d, xk, ld_x, grad + w_offset[k], grad + b_offset[k]);
      if (k == 0) break;
      dense::inputGrad(packed_t.data() + packed_offset[k], kWidth[k], kWidth[k + 1], g, ld_d, Activation::kElu, xk,
                       ld_x, free_buffer->data(), ld_d, n);
      g = free_buffer->data();
      free_buffer = free_buffer == &s.d1 ? &s.d0 : &s.d1;
    }
  }

  void step() {
    gradient();
    adam->step();
  }

  void gradient() {
    const int B = static_cast<int>(batch.obs.cols());
    const float inv_b = 1.f / static_cast<float>(B);
    const int nt = std::min(static_cast<int>(scratch.size()), std::max(1, B / 256));
    const float* values = std::as_const(params).values().data();
#pragma omp parallel num_threads(nt)
    {
      const int t = omp_get_thread_num();
      for (int k = 1; k < kLayers; ++k)
        dense::pack(values + w_offset[k], kWidth[k + 1], true, kWidth[k], kWidth[k + 1],
                    packed_t.data() + packed_offset[k], (t + k) % nt, nt);
      Scratch& s = scratch[t];
      s.grad.setZero();
#pragma omp barrier
      const int per = (B + nt - 1) / nt, c0 = std::min(B, t * per), c1 = std::min(B, c0 + per);
      for (int j0 = c0; j0 < c1; j0 += kChunk) chunk(s, j0, std::min(kChunk, c1 - j0), inv_b);
#pragma omp barrier
      const int P = static_cast<int>(params.size()), pp = (P + nt - 1) / nt;
      const int p0 = std::min(P, t * pp), p1 = std::min(P, p0 + pp);
      auto total = params.grads().segment(p0, p1 - p0);
      total = scratch[0].grad.segment(p0, p1 - p0);
      for (int u = 1; u < nt; ++u) total += scratch[u].grad.segment(p0, p1 - p0);
    }
  }
};

// Both steps compute the same gradient (the parameter layouts agree: weight then bias per layer):
// the largest difference relative to the largest gradient, in the context lines.
double gradientsAgree() {
  const int b = 1000;
  Current current(b);
  ChunkFused fused(b);
  fused.params.values() = current.params.values();
  fused.batch.obs = current.batch.obs;
  fused.batch.actions = current.batch.actions;
  current.params.zeroGrad();
  const auto mean = current.policy->forward(current.batch.obs);
  current.dmean.array() =
      (mean - current.batch.actions).array().colwise() * (current.batch.inv_var.array() * (1.f / static_cast<float>(b)));
  current.policy->backward(current.dmean);
  fused.gradient();
  const double diff = (fused.params.grads() - current.params.grads()).cwiseAbs().maxCoeff();
  const double scale = current.params.grads().cwiseAbs().maxCoeff();
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g", diff / scale);
  benchmark::AddCustomContext("fused_vs_current_max_grad_diff_relative", text);
  return diff / scale;
}
const double kGradientsAgree = gradientsAgree();

template <class Step>
void run(benchmark::State& state) {
  const int batch = static_cast<int>(state.range(0)), threads = static_cast<int>(state.range(1));
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  {
    Step s(batch);
    for (int warm_up = 0; warm_up < 12; ++warm_up) s.step();
    double seconds = 0;
    for (auto _ : state) {
      const auto start = std::chrono::steady_clock::now();
      s.step();
      benchmark::ClobberMemory();
      const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      state.SetIterationTime(dt);
      seconds += dt;
    }
    const double gflops = masa::bench::trainingFlopsPerSample(kShape) * batch *
                          static_cast<double>(state.iterations()) * 1e-9 / seconds;
    state.counters["GFLOPs"] = gflops;
    state.counters["of_peak"] = gflops / masa::bench::measuredPeakGflops(threads);
  }
  omp_set_num_threads(saved);
}

void args(benchmark::internal::Benchmark* b) {
  const char* env = std::getenv("MASA_BENCH_BATCH");
  const int batch = env ? std::atoi(env) : 32768;
  b->ArgNames({"batch", "threads"})->Args({batch, 1})->Args({batch, 2})->UseManualTime()->Unit(benchmark::kMillisecond);
}

BENCHMARK_TEMPLATE(run, Current)->Apply(args);
BENCHMARK_TEMPLATE(run, ChunkFused)->Apply(args);

}  // namespace

