// masa_actor: one actor process. Steps --num-envs environments of the configured task, acting with
// the parameters the learner broadcasts for --run-id, and streams rollouts back over LCM.
//   masa_actor --set task=a1_beam --actor-id 0 --num-envs 64 --run-id 42
// Exit status 0 on a clean stop (SIGINT/SIGTERM or --max-rollouts), 2 on bad input.
#include <csignal>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "actors/actor.hpp"
#include "common/config/run_config.hpp"
#include "common/transport/lcm_url.hpp"

namespace {
std::atomic<bool> g_stop{false};
extern "C" void onSignal(int) { g_stop.store(true); }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"masa actor: simulate environments and stream rollouts to the learner"};
  std::vector<std::string> overrides;
  masa::actor::ActorOptions opt;
  std::string configs = masa::config::defaultConfigsDir();
  app.add_option("--set", overrides, "config override key.path=value (task, method, seed, ppo.*; repeatable)");
  app.add_option("--configs", configs, "configs directory")->capture_default_str();
  app.add_option("--actor-id", opt.actor_id, "actor index, 0-based")->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--num-envs", opt.num_envs, "environments simulated by this actor")
      ->capture_default_str()->check(CLI::Range(1, 1 << 20));
  app.add_option("--url", opt.url, "LCM provider URL (default: " + masa::transport::loopbackUrl() + ")");
  app.add_option("--run-id", opt.run_id, "training run id; parameters of other runs are ignored")->capture_default_str();
  app.add_option("--max-rollouts", opt.max_rollouts, "stop after this many rollouts (default: until signalled)");
  app.add_option("--threads", opt.threads, "OpenMP threads over environments")->capture_default_str()
      ->check(CLI::Range(1, 1 << 20));
  app.add_flag("--start-without-learner", opt.start_without_learner,
               "act with own initial parameters (version 0) instead of waiting for the learner");
  CLI11_PARSE(app, argc, argv);

  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  opt.stop = &g_stop;
  try {
    const auto rc = masa::config::loadRunConfig(configs, overrides);
    masa::actor::Actor actor(rc, opt);
    std::fprintf(stderr, "masa_actor %d: task %s, %d envs, horizon %d, run %lld; %s\n", opt.actor_id,
                 rc.task.c_str(), opt.num_envs, rc.ppo.horizon, static_cast<long long>(opt.run_id),
                 opt.start_without_learner ? "starting with own parameters" : "waiting for parameters");
    const auto sent = actor.run();
    std::fprintf(stderr, "masa_actor %d: stopped after %lld rollouts\n", opt.actor_id, static_cast<long long>(sent));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_actor: %s\n", e.what());
    return 2;
  }
  return 0;
}
