// masa_train: the learner and one actor in one process, over an in-process bus (LocalBus: messages
// handed over as they are, never encoded).
//
// The same Learner and Actor classes as masa_learner / masa_actor, taking turns: the actor collects
// one rollout of all ppo.num_envs environments, the learner updates on it, the actor picks up the
// new parameters. Nothing is lost or stale, so a seed gives the same run on every machine: for
// debugging, learning checks and small experiments. The run directory is the learner's (config,
// metrics, checkpoint, learning curve).
//   masa_train --set task=a1_beam --set method=sa --updates 50 --run-dir runs/a1_sa
//   masa_train --recipe a1_beam --threads 2     (configs/recipes/a1_beam.yaml, its ppo.max_updates updates)
//   masa_train --resume runs/x --updates 1200   (go on to 1200 updates in total, from its checkpoint)
#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "actors/actor.hpp"
#include "actors/environments_snapshot.hpp"
#include "common/core/build_info.hpp"
#include "common/config/batch_shape.hpp"
#include "common/config/run_config.hpp"
#include "common/model/method.hpp"
#include "common/transport/local_bus.hpp"
#include "common/transport/transport.hpp"
#include "learner/learner.hpp"
#include "learner/run_dir/run_directory.hpp"
#include "learner/algorithms/algorithm_catalog.hpp"

namespace {
std::atomic<bool> g_stop{false};
extern "C" void onSignal(int) { g_stop.store(true); }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"masa train: learner and one actor in one process (deterministic, no network)"};
  app.set_version_flag("--version", masa::buildCommit());
  std::vector<std::string> overrides;
  std::string configs = masa::config::defaultConfigsDir();
  std::string run_dir;
  int64_t updates = 0;
  std::string recipe, resume;
  int threads = 1;
  bool quiet = false;
  std::string bus_kind = "local";
  app.add_option("--set", overrides, "key.path=value override (repeatable), e.g. --set task=a1_beam");
  app.add_option("--configs", configs, "configs directory")->capture_default_str();
  app.add_option("--run-dir", run_dir, "run directory (default runs/<task>_<method>_inprocess_<seed>_<time>)");
  app.add_option("--recipe", recipe, "a recipe of configs/recipes/ (or a YAML file), applied before --set");
  app.add_option("--updates", updates, "updates (PPO) or rounds (off-policy) to make in total (default: ppo.max_updates, or sac.env_steps in rounds)")
      ->check(CLI::PositiveNumber);
  app.add_option("--threads", threads, "OpenMP threads over the environments")->capture_default_str()
      ->check(CLI::Range(1, 1024));
  app.add_option("--resume", resume, "go on with the run in this directory (its config.yaml and checkpoint.bin)");
  app.add_flag("--quiet", quiet, "no progress line per update");
  app.add_option("--bus", bus_kind,
                 "local: messages handed over as they are; memq: through LCM's in-process provider, each "
                 "message encoded, guarded and decoded (as before 2026-12-04; the same run, slower)")
      ->check(CLI::IsMember({"local", "memq"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  try {
    if (!recipe.empty()) overrides.insert(overrides.begin(), "@" + recipe);
    if (!resume.empty()) {
      if (!recipe.empty()) throw std::runtime_error("--resume goes on with the run's own config: no --recipe");
      if (!run_dir.empty() && run_dir != resume) throw std::runtime_error("--resume names the run directory: no --run-dir");
      run_dir = resume;
    }
    const auto rc = masa::config::loadRunConfig(configs, overrides, resume.empty() ? "" : resume + "/config.yaml");
    masa::config::checkBatchShape(rc, 1);
    if (updates == 0) updates = rc.rollout.max_updates;
    if (run_dir.empty())
      run_dir = masa::learner::defaultRunDir(rc.task + "_" + masa::model::methodName(rc.method) + "_inprocess", rc.seed);
    std::unique_ptr<masa::transport::MessageBus> bus;
    if (bus_kind == "memq") bus = std::make_unique<masa::transport::Transport>("memq://", std::nullopt);
    else bus = std::make_unique<masa::transport::LocalBus>();
    masa::learner::LearnerOptions lo;
    lo.bus = bus.get();
    lo.run_dir = run_dir;
    lo.run_id = 1;
    lo.verbose = !quiet;
    lo.resume = !resume.empty();
    lo.make_algorithm = masa::learner::makeAlgorithm;
    masa::learner::Learner learner(rc, lo);
    learner.setMaxUpdates(updates);

    masa::actor::ActorOptions ao;
    ao.num_envs = rc.rollout.num_envs;
    ao.run_id = lo.run_id;
    ao.threads = threads;
    ao.incarnation = 1;  // bit-identical chunks from run to run
    ao.heartbeat_interval_s = 1e9;  // nobody listens
    ao.stop = &g_stop;
    masa::actor::Actor actor(rc, ao, bus.get());
    std::fprintf(stderr, "masa_train: %s / %s, %d envs x %d steps per update, %lld updates, run dir %s\n",
                 rc.task.c_str(), masa::model::methodName(rc.method).c_str(), rc.rollout.num_envs, rc.rollout.horizon,
                 static_cast<long long>(updates), learner.runDir().c_str());
    // The environments go beside the learner's checkpoint (actor_state.bin), as they were between
    // the two rollouts the checkpoint lies between: a resume goes on exactly, as if never stopped.
    // Without them (an older run, a mismatch) the environments start from a reset; say which.
    const std::string env_path = learner.runDir() + "/actor_state.bin";
    if (lo.resume) {
      const std::string why = masa::actor::resumeEnvironments(env_path, learner.updates(), actor);
      std::fprintf(stderr, "masa_train: resumed at update %lld (%lld env steps); %s\n",
                   static_cast<long long>(learner.updates()), static_cast<long long>(learner.envSteps()),
                   why.empty() ? "the environments go on as they were (actor_state.bin)"
                               : ("the environments start from a reset here (" + why + ")").c_str());
    }
    masa::actor::EnvironmentsSnapshot snapshot;
    snapshot.take(actor, learner.updates());
    learner.setCheckpointHook([&](int64_t at) { snapshot.writeIfAt(at, env_path); });

    while (!g_stop.load() && learner.updates() < updates) {
      if (!actor.pollParams(0)) {
        learner.publishParams();  // the first broadcast may predate the actor's subscription
        if (!actor.pollParams(0)) throw std::runtime_error("the actor received no parameters from the learner");
      }
      if (!actor.collectAndPublish()) break;  // stopped mid-rollout: the last snapshot is the boundary
      snapshot.take(actor, learner.updates() + 1);  // between this rollout and the next: the update it makes
      bool updated = false;
      for (int tries = 0; !updated && tries < 100; ++tries) updated = learner.step(0);
      if (!updated) throw std::runtime_error("the learner made no update from a whole rollout (see its warnings)");
    }
    learner.writeCheckpoint();
    learner.renderLearningCurve();
    std::fprintf(stderr, "masa_train: %lld updates, %lld env steps; run dir %s\n",
                 static_cast<long long>(learner.updates()), static_cast<long long>(learner.envSteps()),
                 learner.runDir().c_str());
    if (const std::string kernels = learner.algorithm().kernelSummary(); !kernels.empty())
      std::fprintf(stderr, "masa_train: MLP chunk width: %s\n", kernels.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_train: %s\n", e.what());
    return 2;
  }
  return 0;
}
