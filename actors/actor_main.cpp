// masa_actor: one actor process. Steps --num-envs environments of the configured task, acting with
// the parameters the learner broadcasts for --run-id, and streams rollouts back over LCM.
//   masa_actor --set task=a1_beam --actor-id 0 --num-envs 64 --run-id 42 --key-file RUN_DIR/run.key
// Every message is authenticated with the learner's run key (--key-file); --no-auth turns that off.
// In a signed run, --roster RUN_DIR/roster --signing-key RUN_DIR/keys/actorN.key instead: the actor
// signs with its own key and believes parameters only from the roster's learner.
// Exit status 0 on a clean stop (SIGINT/SIGTERM or --max-rollouts), 2 on bad input.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "actors/actor.hpp"
#include "common/core/build_info.hpp"
#include "common/core/summary_stats.hpp"
#include "common/config/run_config.hpp"
#include "common/cluster/job_plan.hpp"
#include "common/cluster/mpi_job.hpp"
#include "common/transport/job_roster.hpp"
#include "common/transport/lcm_url.hpp"
#include "common/transport/run_key.hpp"

namespace {
std::atomic<bool> g_stop{false};
extern "C" void onSignal(int) { g_stop.store(true); }
// An actor of an MPI job: the plan learner rank 0 shares (run id, URLs, the run key or a signed
// job) and this actor's keys made in memory; any failure ends the whole job.
void takeJobPlan(masa::cluster::MpiJob& job, masa::actor::ActorOptions& opt, bool& no_auth, std::string& key_file) {
  try {
    // Before the plan, as every process of the job does (job_roster.hpp).
    auto job_keys = masa::transport::jobSignedMode(
        {masa::transport::Role::kActor, static_cast<uint32_t>(job.roleIndex())},
        [&](const std::vector<uint8_t>& mine) { return job.gatherFromEveryProcess(mine); });
    std::vector<uint8_t> bytes;
    job.shareFromLearnerZero(bytes);
    const auto plan = masa::cluster::JobPlan::decode(bytes);
    opt.actor_id = job.roleIndex();
    opt.run_id = plan.run_id;
    opt.url = plan.url;
    // Actor i reports to learner rank i mod (number of ranks).
    opt.rollout_url =
        masa::transport::rankRolloutUrl(plan.url, opt.actor_id % job.learnerCount(), job.learnerCount());
    if (plan.key) {
      masa::transport::RunKey k;
      k.bytes = *plan.key;
      opt.run_key = k;
    }
    if (plan.signed_job) opt.signed_mode = std::move(job_keys);
    no_auth = !plan.key && !plan.signed_job;
    key_file = plan.key ? "(from learner rank 0)" : plan.signed_job ? "(a key made in memory)" : "";
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_actor: %s\n", e.what());
    job.abort(2);
  }
}

// How this actor authenticates (said on stderr): the MPI job's plan, a roster and its own key (a
// signed run), no authentication, or the learner's run key read from key_file.
void chooseAuthentication(masa::actor::ActorOptions& opt, const masa::cluster::MpiJob* job, const std::string& roster_file,
                       const std::string& signing_key, const std::string& key_file, bool no_auth) {
  if (job) {
    std::fprintf(stderr, "masa_actor %d: actor %d of %d in an MPI job, rollouts to learner rank %d on %s; %s%s\n",
                 opt.actor_id, opt.actor_id, job->actorCount(), opt.actor_id % job->learnerCount(),
                 opt.rollout_url.c_str(),
                 opt.signed_mode ? "messages signed with a key made in memory, "
                 : opt.run_key   ? "messages authenticated with the job's run key"
                                 : "WARNING: no message authentication (--no-auth)",
                 opt.signed_mode ? (masa::integrity::keyFingerprint(opt.signed_mode->signer->publicKey()) +
                                    ", senders checked against the roster of the MPI job").c_str()
                                 : "");
  } else if (!roster_file.empty()) {
    opt.signed_mode = masa::transport::loadSignedMode(
        roster_file, signing_key, {masa::transport::Role::kActor, static_cast<uint32_t>(opt.actor_id)});
    std::fprintf(stderr, "masa_actor %d: messages signed with %s (%s), senders checked against the roster %s\n",
                 opt.actor_id, signing_key.c_str(),
                 masa::integrity::keyFingerprint(opt.signed_mode->signer->publicKey()).c_str(), roster_file.c_str());
  } else if (no_auth) {
    std::fprintf(stderr, "masa_actor %d: WARNING: --no-auth: messages are neither signed nor checked; anyone who "
                         "can reach this network can make this actor act with their parameters\n", opt.actor_id);
  } else {
    opt.run_key = masa::transport::readRunKey(key_file);
    std::fprintf(stderr, "masa_actor %d: messages authenticated with the run key %s (key id %s)\n", opt.actor_id,
                 key_file.c_str(), opt.run_key->id().c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  // Started by mpirun or srun beside the learner ranks (docs/scaling.md): the job says who this
  // actor is, which run, where its rollouts go, and how to authenticate (a signed job: its own key,
  // made in memory, and the roster gathered over MPI); no key file, run id or URL is needed.
  std::unique_ptr<masa::cluster::MpiJob> job;
  try {
    if (masa::cluster::launchedByMpi()) job = std::make_unique<masa::cluster::MpiJob>(masa::cluster::Role::kActor);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_actor: %s\n", e.what());
    return 2;
  }
  CLI::App app{"masa actor: simulate environments and stream rollouts to the learner"};
  app.set_version_flag("--version", masa::buildCommit());
  std::vector<std::string> overrides;
  masa::actor::ActorOptions opt;
  std::string configs = masa::config::defaultConfigsDir();
  app.add_option("--set", overrides, "config override key.path=value (task, method, seed, ppo.*; repeatable)");
  app.add_option("--configs", configs, "configs directory")->capture_default_str();
  std::string run_config;
  app.add_option("--run-config", run_config,
                 "a run directory's config.yaml, read instead of the task file (to join a resumed run)")
      ->check(CLI::ExistingFile);
  app.add_option("--actor-id", opt.actor_id, "actor index, 0-based")->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--num-envs", opt.num_envs, "environments simulated by this actor")
      ->capture_default_str()->check(CLI::Range(1, 1 << 20));
  app.add_option("--url", opt.url, "LCM provider URL (default: " + masa::transport::loopbackUrl() + ")");
  app.add_option("--run-id", opt.run_id, "training run id; parameters of other runs are ignored")->capture_default_str();
  app.add_option("--max-rollouts", opt.max_rollouts, "stop after this many rollouts (default: until signalled)");
  app.add_option("--threads", opt.threads, "OpenMP threads over environments")->capture_default_str()
      ->check(CLI::Range(1, 1 << 20));
  app.add_option("--await-params-s", opt.await_params_s,
                 "after each rollout, wait up to this long for newer parameters until the learner has answered "
                 "once (0: never wait; keeps data on-policy)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--await-params-max-s", opt.await_params_max_s,
                 "then the wait is 1.5x the learner's answer time, up to this long (the parameters that follow "
                 "the learner's evaluation, every runner.eval_every updates: this long)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--await-params-min-s", opt.await_params_min_s, "... and at least this long")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--learner-silence-pause-s", opt.learner_silence_pause_s,
                 "stop publishing after hearing nothing from the learner this long (0: never)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--learner-silence-exit-s", opt.learner_silence_exit_s,
                 "exit after hearing nothing from the learner this long (0: never)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_flag("--start-without-learner", opt.start_without_learner,
               "act with own initial parameters (version 0) instead of waiting for the learner");
  app.add_option("--incarnation", opt.incarnation,
                 "this process's incarnation in its rollout chunks (default: from the clock and the process id, so "
                 "that the learner tells a restarted actor's rollouts from its previous process's)")
      ->check(CLI::PositiveNumber);
  std::string key_file;
  bool no_auth = false;
  auto* key_opt = app.add_option("--key-file", key_file,
                                 "the learner's run key (its RUN_DIR/run.key), which every message is authenticated with");
  auto* no_auth_opt = app.add_flag("--no-auth", no_auth, "send and accept messages without authentication (anyone on the network can "
                                     "then make this actor act with their parameters)")->excludes(key_opt);
  std::string roster_file, signing_key;
  auto* roster_opt = app.add_option("--roster", roster_file,
                                    "a signed run: the run's roster (public keys and channels per sender, masa_roster)")
                         ->excludes(key_opt)->excludes(no_auth_opt);
  app.add_option("--signing-key", signing_key, "a signed run: this actor's private key file (mode 0600)")->needs(roster_opt);
  roster_opt->needs("--signing-key");
  // Fault injection for tests of the learner's loss handling; never for training.
  app.add_option("--drop-chunks-percent", opt.drop_chunks_percent,
                 "FAULT INJECTION (tests only): throw away this percentage of rollout chunks instead of sending them")
      ->check(CLI::Range(0.0, 100.0))->group("Fault injection");
  app.add_option("--drop-seed", opt.drop_seed, "seed of the generator that picks the chunks to throw away")
      ->capture_default_str()->group("Fault injection");
  CLI11_PARSE(app, argc, argv);
  if (job) takeJobPlan(*job, opt, no_auth, key_file);
  if (key_file.empty() && !no_auth && roster_file.empty()) {
    std::fprintf(stderr, "masa_actor: no key: give --roster RUN_DIR/roster with --signing-key RUN_DIR/keys/actorN.key "
                         "(a signed run), or --key-file RUN_DIR/run.key (the learner's run key), or --no-auth to run "
                         "without message authentication\n");
    return 2;
  }

  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  opt.stop = &g_stop;
  try {
    const auto rc = masa::config::loadRunConfig(configs, overrides, run_config);
    chooseAuthentication(opt, job.get(), roster_file, signing_key, key_file, no_auth);
    masa::actor::Actor actor(rc, opt);
    // In an MPI job the actors end when the learner ranks say training is over.
    std::thread watcher;
    std::atomic<bool> acting{true};
    if (job)
      watcher = std::thread([&] {
        while (acting.load() && !job->trainingFinished()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
        g_stop.store(true);
      });
    struct Join {
      std::thread& t;
      std::atomic<bool>& acting;
      ~Join() {
        acting.store(false);
        if (t.joinable()) t.join();
      }
    } join{watcher, acting};
    std::fprintf(stderr, "masa_actor %d: task %s, %d envs, horizon %d, run %lld; %s\n", opt.actor_id,
                 rc.task.c_str(), opt.num_envs, rc.rollout.horizon, static_cast<long long>(opt.run_id),
                 opt.start_without_learner ? "starting with own parameters" : "waiting for parameters");
    if (opt.drop_chunks_percent > 0)
      std::fprintf(stderr, "masa_actor %d: FAULT INJECTION: throwing away %g%% of rollout chunks (seed %llu)\n",
                   opt.actor_id, opt.drop_chunks_percent, static_cast<unsigned long long>(opt.drop_seed));
    const auto sent = actor.run();
    std::fprintf(stderr, "masa_actor %d: stopped after %lld rollouts (incarnation %lld), %lld chunks sent", opt.actor_id,
                 static_cast<long long>(sent), static_cast<long long>(actor.incarnation()),
                 static_cast<long long>(actor.chunksPublished()));
    if (opt.drop_chunks_percent > 0)
      std::fprintf(stderr, ", %lld thrown away by fault injection", static_cast<long long>(actor.chunksDropped()));
    std::fprintf(stderr, "\n");
    if (!actor.collectSeconds().empty())
      std::fprintf(stderr, "masa_actor %d: a rollout took %.3f s to collect and %.3f s waiting for parameters after it "
                   "(medians of the last %zu)\n", opt.actor_id, masa::stats::median(actor.collectSeconds()),
                   actor.awaitSeconds().empty() ? 0.0 : masa::stats::median(actor.awaitSeconds()),
                   actor.collectSeconds().size());
    std::fprintf(stderr, "masa_actor %d: parameter messages refused after decoding %lld; rejected before decoding: %s\n",
                 opt.actor_id, static_cast<long long>(actor.paramsRejected()), actor.transport().rejectSummary().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_actor: %s\n", e.what());
    if (job) job->abort(2);
    return 2;
  }
  return 0;
}
