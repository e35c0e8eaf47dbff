// The fp32 FMA peak of the machine the benchmark runs on, measured, not assumed: shares of peak
// ("of_peak") quoted against a constant from another CPU were wrong on every other CPU (issue #14:
// 0.41 printed on a Xeon where the truth was 0.33). Each thread runs 12 independent FMA chains on
// the widest vectors the build targets (AVX-512, else AVX2/FMA), enough to cover the latency of
// two FMA ports; the best of a few short runs counts. The CPU model goes into the benchmark's
// context so every recorded result names the machine it was measured on.
#pragma once

#include <benchmark/benchmark.h>
#include <immintrin.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <map>
#include <mutex>
#include <string>

namespace masa::bench {

inline std::string cpuModel() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) {
      const size_t colon = line.find(':');
      return colon == std::string::npos ? line : line.substr(colon + 2);
    }
  return "unknown CPU";
}

namespace detail {

// FLOPs of `iterations` rounds of 12 FMA chains on one thread; the result feeds a sink so that
// the compiler keeps the work.
inline double fmaChains(long iterations, float* sink) {
#if defined(__AVX512F__)
  using V = __m512;
  constexpr int kLanes = 16;
  auto set1 = [](float x) { return _mm512_set1_ps(x); };
  auto fma = [](V a, V b, V c) { return _mm512_fmadd_ps(a, b, c); };
  auto sum = [](V a) {  // (not _mm512_reduce_add_ps: GCC 12 warns falsely inside it)
    alignas(64) float f[16];
    _mm512_store_ps(f, a);
    float s = 0;
    for (float x : f) s += x;
    return s;
  };
#elif defined(__FMA__)
  using V = __m256;
  constexpr int kLanes = 8;
  auto set1 = [](float x) { return _mm256_set1_ps(x); };
  auto fma = [](V a, V b, V c) { return _mm256_fmadd_ps(a, b, c); };
  auto sum = [](V a) {
    alignas(32) float f[8];
    _mm256_store_ps(f, a);
    float s = 0;
    for (float x : f) s += x;
    return s;
  };
#else
#error "machine_peak.hpp needs FMA (build with -march=native on an x86-64 CPU with FMA)"
#endif
  V acc[12];
  for (int i = 0; i < 12; ++i) acc[i] = set1(0.001f * static_cast<float>(i));
  const V a = set1(0.999999f), b = set1(1e-7f);
  for (long it = 0; it < iterations; ++it)
    for (int i = 0; i < 12; ++i) acc[i] = fma(acc[i], a, b);
  float s = 0;
  for (int i = 0; i < 12; ++i) s += sum(acc[i]);
  *sink += s;
  return 2.0 * kLanes * 12.0 * static_cast<double>(iterations);
}

}  // namespace detail

// Measured fp32 FMA peak in GFLOP/s for `threads` threads (cached per thread count).
inline double measuredPeakGflops(int threads) {
  static std::mutex mutex;
  static std::map<int, double> cache;
  std::lock_guard<std::mutex> lock(mutex);
  if (auto it = cache.find(threads); it != cache.end()) return it->second;
  constexpr long kIterations = 20'000'000;  // about 0.1 s a run at 3 GHz
  double best = 0;
  for (int run = 0; run < 3; ++run) {
    double flops = 0;
    float sink = 0;
    const auto t0 = std::chrono::steady_clock::now();
#pragma omp parallel num_threads(threads) reduction(+ : flops, sink)
    flops += detail::fmaChains(kIterations, &sink);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    benchmark::DoNotOptimize(sink);
    best = std::max(best, flops / s * 1e-9);
  }
  cache[threads] = best;
  benchmark::AddCustomContext("fp32_fma_peak_gflops_" + std::to_string(threads) + "t", std::to_string(best));
  return best;
}

// Names the CPU and its measured peaks on 1 and 2 threads in the benchmark's context (call once,
// before the benchmarks run: a static initializer does).
inline bool describeMachine() {
  benchmark::AddCustomContext("cpu_model", cpuModel());
  for (int threads : {1, 2}) measuredPeakGflops(threads);
  return true;
}

}  // namespace masa::bench
