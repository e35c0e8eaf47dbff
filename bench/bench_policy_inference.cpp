// The policy mean of every shipped policy (tasks/<task>/policy/policy.bin) as the robot runner and
// the actors compute it: ActorCritic::actMean on 1 observation (N agent columns through Phi for
// MASA), on the actors' path and frozen as the robot runner runs it (weights packed for N columns),
// and on 16 (a small batch of environments), on one thread (issue #14).
//
// FLOPs count Phi's products only (2 * in * out per layer and agent column); normalization, agent
// stacking and the output maps are elementwise and not counted. of_peak = GFLOP/s over one core's
// measured FMA peak; its inverse is how far the step is from the FLOP bound.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <random>
#include <string>
#include <vector>

#include "common/policy/policy_file.hpp"
#include "machine_peak.hpp"
#include "mlp_flops.hpp"

namespace {

const bool kMachineDescribed = masa::bench::describeMachine();

const std::vector<std::string> kTasks{"a1_beam", "ant_acrobatic", "trifinger_lift", "humanoid_tightrope",
                                      "humanoid_dribbling"};

double phiFlopsPerObservation(const masa::model::ActorCritic<float>& model) {
  return masa::bench::forwardFlopsPerSample(model.policy().net().shape()) * model.policy().maps().num_agents;
}

void BM_PolicyMean(benchmark::State& state) {
  const std::string& task = kTasks[static_cast<size_t>(state.range(0))];
  const int batch = static_cast<int>(state.range(1));
  const bool frozen = state.range(2) != 0;
  const int saved_threads = omp_get_max_threads();
  omp_set_num_threads(1);
  {
    masa::policy::LoadedPolicy lp =
        masa::policy::loadPolicyFile(std::string(MASA_SOURCE_DIR) + "/tasks/" + task + "/policy/policy.bin");
    masa::Rng rng(1);
    std::normal_distribution<float> normal(0.f, 1.f);
    masa::Mat<float> obs(lp.model->obsDim(), batch);
    for (float& v : obs.reshaped()) v = normal(rng);
    if (frozen) lp.model->freezeForInference();  // as the robot runner does
    lp.model->actMean(obs);                      // buffers (and packs) made before the timing
    for (auto _ : state) benchmark::DoNotOptimize(lp.model->actMean(obs).data());
    const double flops = phiFlopsPerObservation(*lp.model) * batch;
    const double gflops = flops * static_cast<double>(state.iterations()) * 1e-9;
    state.counters["GFLOP/s"] = benchmark::Counter(gflops, benchmark::Counter::kIsRate);
    state.counters["of_peak"] =
        benchmark::Counter(gflops / masa::bench::measuredPeakGflops(1), benchmark::Counter::kIsRate);
    state.counters["columns"] = lp.model->policy().maps().num_agents * batch;
    state.SetLabel(task);
  }
  omp_set_num_threads(saved_threads);
}

void args(benchmark::internal::Benchmark* b) {
  b->ArgNames({"task", "batch", "frozen"});
  for (int t = 0; t < static_cast<int>(kTasks.size()); ++t) b->Args({t, 1, 0})->Args({t, 1, 1})->Args({t, 16, 0});
  b->Unit(benchmark::kMicrosecond)->UseRealTime();
}

BENCHMARK(BM_PolicyMean)->Apply(args);

}  // namespace
