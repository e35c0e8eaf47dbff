// Gradient steps per second of the off-policy learner (issue #34) at the recipe's batch (256) and
// networks (policy and each Q: 256, 256, ELU, float), on 1 and 2 threads, for SA and MASA on A1
// Beam and Humanoid Tightrope (each splits into 2 agents under MASA) and TriFinger Lift (3 agents,
// the off-policy recipe's task of issue #50), SAC and TD3.
//   SAC step: target (policy on o', twin target Q), twin Q step, actor step through Q, temperature,
//             Polyak move (SacTrainer::step)
//   TD3 step: target policy smoothing, twin Q step, every 2nd step the actor and the targets
// The batch is drawn once from random data; the learner normalizes nothing (the identity).
//
// Counters: steps_per_s, GFLOPs and of_peak (that over this machine's measured fp32
// FMA peak for the threads used, machine_peak.hpp). FLOPs count the networks' matrix products per
// sample: F_pi and F_q = 2 x (the weights of the policy, of both Qs) x (agents each network runs
// on: 1 for SA, the group's order for MASA; MASA's pooled head is counted per agent, an excess
// under 1%). A SAC step is B x (4 F_pi + 6 F_q): the policy forward on o' and its training step
// (3x: forward, dx, dW); the target twin Q forward (1x), the twin Q training step (3x), and the
// twin Q forward and dx in the actor step (2x). A TD3 step with policy delay d is
// B x (F_pi + 4 F_q + (3 F_pi + F_q) / d): the target policy and the target twin Q forward, the
// twin Q training step every step; the actor step (policy 3x, Q_1's forward and dx, each half of a
// twin Q pass) every d-th.
// Biases, activations and the losses are not counted.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include "common/config/sac_config.hpp"
#include "common/model/sac_policy.hpp"
#include "learner/offline/twin_q.hpp"
#include "learner/sac/sac_critic_maps.hpp"
#include "learner/sac/trainer_factory.hpp"
#include "machine_peak.hpp"

namespace {

using namespace masa;

const bool kMachineDescribed = bench::describeMachine();

const char* const kTasks[] = {"a1_beam", "humanoid_tightrope", "trifinger_lift"};

const sym::SymmetrySpec& spec(int task) {
  static const sym::SymmetrySpec specs[] = {
      sym::SymmetrySpec::load((std::filesystem::path(MASA_SOURCE_DIR) / "configs/specs/a1_beam.yaml").string()),
      sym::SymmetrySpec::load((std::filesystem::path(MASA_SOURCE_DIR) / "configs/specs/humanoid_tightrope.yaml").string()),
      sym::SymmetrySpec::load((std::filesystem::path(MASA_SOURCE_DIR) / "configs/specs/trifinger_lift.yaml").string())};
  return specs[task];
}

// 2 x the weights (matrices, not biases) of a parameter set, times the agents its network runs on.
double forwardFlopsPerSample(const nn::ParameterSet<float>& params, int agents) {
  double weights = 0;
  for (const auto& s : params.segments())
    if (s.cols > 1) weights += static_cast<double>(s.rows) * s.cols;
  return 2.0 * weights * agents;
}

// Args: task (0 A1 Beam, 1 Humanoid Tightrope, 2 TriFinger Lift), MASA (0 SA, 1 MASA), TD3 (0 SAC, 1 TD3), threads.
void BM_OffPolicyStep(benchmark::State& state) {
  const int task = static_cast<int>(state.range(0));
  const model::Method method = state.range(1) ? model::Method::kMasa : model::Method::kSa;
  const bool td3 = state.range(2) != 0;
  const int threads = static_cast<int>(state.range(3));
  omp_set_num_threads(threads);
  const sym::SymmetrySpec& sp = spec(task);

  sac::SacConfig sc;  // the sac section's defaults: batch 256, [256, 256] networks
  sc.algorithm = td3 ? "td3" : "sac";
  sac::SacPolicyShape shape;
  shape.method = method;
  shape.hidden = sc.policy_hidden;
  sac::SacPolicy<float> policy(sp, shape);
  offline::TwinQ<float> q(sp, sac::twinQMaps(method, sp), sc.q_hidden, nn::Activation::kElu);
  offline::TwinQ<float> q_target(sp, sac::twinQMaps(method, sp), sc.q_hidden, nn::Activation::kElu);
  Rng rng(7);
  policy.initialize(rng);
  q.initialize(rng);
  q_target.moveTowards(q, 1.0f);
  const auto trainer = sac::makeTrainer(sc, sp, policy, q, q_target);

  const int B = sc.batch_size;
  sac::ReplayBatch<float> batch;
  batch.resize(sp.obsDim(), sp.actDim(), B);
  std::normal_distribution<float> g;
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (float* m : {batch.obs.data(), batch.next_obs.data()})
    for (int i = 0; i < sp.obsDim() * B; ++i) m[i] = g(rng);
  for (int i = 0; i < sp.actDim() * B; ++i) batch.actions.data()[i] = u(rng);
  for (int i = 0; i < B; ++i) batch.rewards(0, i) = g(rng), batch.discount(0, i) = 0.99f;

  // First touch of every buffer and the MLP chunk-width tuning (optimized_net.hpp) stay out of
  // the timing.
  for (int warm_up = 0; warm_up < 30; ++warm_up) trainer->step(batch, rng);
  double seconds = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(trainer->step(batch, rng));
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  const double steps = static_cast<double>(state.iterations());
  state.counters["steps_per_s"] = steps / seconds;
  {
    const int agents = method == model::Method::kMasa ? sp.numAgents() : 1;
    const double f_pi = forwardFlopsPerSample(policy.params(), agents), f_q = forwardFlopsPerSample(q.params(), agents);
    const double flops_per_step = td3 ? B * (f_pi + 4 * f_q + (3 * f_pi + f_q) / sc.td3_policy_delay)
                                      : B * (4 * f_pi + 6 * f_q);
    const double gflops = flops_per_step * steps * 1e-9 / seconds;
    state.counters["MFLOP_per_step"] = flops_per_step * 1e-6;
    state.counters["GFLOPs"] = gflops;
    state.counters["of_peak"] = gflops / bench::measuredPeakGflops(threads);
  }
  state.SetLabel(std::string(kTasks[task]) + (method == model::Method::kMasa ? " MASA " : " SA ") + sc.algorithm);
}

void args(benchmark::internal::Benchmark* b) {
  b->ArgNames({"task", "masa", "td3", "threads"});
  for (int task : {0, 1, 2})
    for (int masa : {0, 1})
      for (int td3 : {0, 1})
        for (int threads : {1, 2}) b->Args({task, masa, td3, threads});
  b->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
}

BENCHMARK(BM_OffPolicyStep)->Apply(args);

}  // namespace
