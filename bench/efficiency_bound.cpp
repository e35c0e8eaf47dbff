// The throughput a training run could reach on this machine if nothing ever waited: every core
// either steps environments (with inference) or runs the learner's update, so
//     bound = cores / (t_env + t_learn)      env steps per second
// t_env:   one core's seconds per env step: the real Actor's rollout (physics, observation,
//          batched inference, sampling, chunking) on one thread, per env step;
// t_learn: the learner's core-seconds per env step: the real Learner's update of one batch
//          (intake, normalizers, GAE, all mini-epochs of policy and critic for all agents,
//          parameter broadcast, metrics) on one thread, divided by the batch's env steps.
// Prints both and the bound; bench/e2e_efficiency.sh sets it against deploy/train.sh's fps.
//   bench_efficiency_bound --recipe a1_beam [--set key=value ...] [--rounds 3]
#include <CLI/CLI.hpp>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "actors/actor.hpp"
#include "common/transport/channels.hpp"
#include "common/config/run_config.hpp"
#include "learner/learner.hpp"
#include "learner/ppo_algorithm.hpp"

namespace {
double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Throughput bound cores / (t_env + t_learn) of a training configuration on this machine"};
  std::string recipe;
  std::vector<std::string> overrides;
  int rounds = 3, cores = static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN));
  app.add_option("--recipe", recipe, "a recipe of configs/recipes/");
  app.add_option("--set", overrides, "config override key.path=value (repeatable)");
  app.add_option("--rounds", rounds, "measured rollouts and updates (after one warm-up each)")->capture_default_str();
  app.add_option("--cores", cores, "cores of the bound (default: this machine's)")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    if (!recipe.empty()) overrides.insert(overrides.begin(), "@" + recipe);
    overrides.push_back("runner.eval_every=0");  // measured apart: an evaluation is not training
    overrides.push_back("runner.plot_every=0");
    overrides.push_back("runner.checkpoint_every=0");
    const auto rc = masa::config::loadRunConfig(masa::config::defaultConfigsDir(), overrides);
    const std::string dir = (std::filesystem::temp_directory_path() / ("masa_bound_" + std::to_string(getpid()))).string();
    masa::learner::LearnerOptions lo;
    lo.make_algorithm = masa::learner::makePpoAlgorithm;
    lo.url = "memq://";
    lo.run_dir = dir;
    lo.run_id = 1;
    lo.verbose = false;
    omp_set_num_threads(1);
    masa::learner::Learner learner(rc, lo);
    masa::actor::ActorOptions ao;
    ao.num_envs = rc.rollout.num_envs;
    ao.run_id = 1;
    ao.threads = 1;
    ao.incarnation = 1;  // bit-identical chunks from run to run
    ao.heartbeat_interval_s = 1e9;
    masa::actor::Actor actor(rc, ao, &learner.transport());
    // What travels: rollout bytes per env step and one parameter message (the cost model's network terms).
    double rollout_bytes = 0, params_bytes = 0;
    learner.transport().subscribeRaw(masa::transport::kRolloutChannel, [&](const void*, int n) { rollout_bytes += n; });
    learner.transport().subscribeRaw(masa::transport::kPolicyChannel, [&](const void*, int n) { params_bytes = n; });
    const double steps = static_cast<double>(rc.rollout.num_envs) * rc.rollout.horizon;
    std::vector<double> t_env, t_learn;
    for (int r = 0; r <= rounds; ++r) {
      if (!actor.pollParams(0)) {
        learner.publishParams();
        if (!actor.pollParams(0)) throw std::runtime_error("the actor received no parameters");
      }
      double t0 = now();
      actor.collectAndPublish();
      const double env = (now() - t0) / steps;
      t0 = now();
      bool updated = false;
      for (int k = 0; k < 100 && !updated; ++k) updated = learner.step(0);
      if (!updated) throw std::runtime_error("the learner made no update");
      const double learn = (now() - t0) / steps;
      if (r == 0) continue;  // warm-up: first touch of every buffer
      t_env.push_back(env);
      t_learn.push_back(learn);
    }
    std::filesystem::remove_all(dir);
    const double e = median(t_env), l = median(t_learn);
    std::printf("config: %s / %s, %d envs x %d steps, minibatch %d x %d mini-epochs\n", rc.task.c_str(),
                masa::model::methodName(rc.method).c_str(), rc.rollout.num_envs, rc.rollout.horizon, rc.ppo.minibatch_size,
                rc.ppo.mini_epochs);
    std::printf("t_env   %.2f us per env step (one core: physics, inference, sampling, chunking)\n", e * 1e6);
    std::printf("t_learn %.2f us per env step (learner core-seconds: intake, GAE, all mini-epochs)\n", l * 1e6);
    std::printf("share of the learner: %.2f\n", l / (e + l));
    std::printf("bound %.0f env steps/s on %d cores\n", cores / (e + l), cores);
    std::printf("wire %.1f bytes per env step (rollout chunks), parameters %.0f bytes a message\n",
                rollout_bytes / (steps * (rounds + 1)), params_bytes);
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "bench_efficiency_bound: %s\n", ex.what());
    return 2;
  }
  return 0;
}
