// masa_learner: the training process. Actors (masa_actor) send rollouts; this runs PPO and
// broadcasts parameters.
//   masa_learner --set task=trifinger_lift --set method=masa
//   masa_learner --resume runs/trifinger_lift_masa_0_20260101-120000
// Every message is authenticated with the run key (--key-file, default RUN_DIR/run.key, made when
// missing); --no-auth turns that off.
#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <ctime>
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "common/build_info/build_info.hpp"
#include "common/config/run_config.hpp"
#include "common/model/method.hpp"
#include "common/transport/lcm_url.hpp"
#include "common/transport/run_key.hpp"
#include "learner/intake/drop_reason.hpp"
#include "learner/learner.hpp"

namespace {

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");

void onSignal(int) { g_stop.store(true); }

std::string timestamp() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y%m%d-%H%M%S", &tm);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"masa learner: multi-agent PPO fed by actors over LCM"};
  app.set_version_flag("--version", masa::buildCommit());
  std::vector<std::string> overrides;
  std::string configs = masa::config::defaultConfigsDir();
  std::string run_dir, resume_dir, url;
  int64_t run_id = 0;
  int64_t max_updates = -1;
  app.add_option("--set", overrides, "key.path=value override (repeatable), e.g. --set ppo.horizon=8");
  app.add_option("--configs", configs, "configs directory (defaults.yaml, tasks/, specs/)");
  app.add_option("--run-dir", run_dir, "run directory (default runs/<task>_<method>_<seed>_<timestamp>)");
  app.add_option("--resume", resume_dir, "continue the run in this directory from its checkpoint.bin, with its config.yaml (--set still applies)");
  // The same default as masa_actor: loopback multicast with a receive buffer large enough for chunks.
  url = masa::transport::loopbackUrl();
  app.add_option("--url", url, "LCM provider URL")->capture_default_str();
  app.add_option("--run-id", run_id, "run id actors must carry (default: random, or the checkpoint's)");
  app.add_option("--max-updates", max_updates, "stop after this many updates in total (default ppo.max_epochs)");
  std::string key_file;
  bool no_auth = false;
  auto* key_opt = app.add_option("--key-file", key_file,
                                 "the run key every message is authenticated with (default: RUN_DIR/run.key, made "
                                 "when missing; give the actors the same file)");
  app.add_flag("--no-auth", no_auth, "send and accept messages without authentication (anyone on the network can "
                                     "then feed this run rollouts)")->excludes(key_opt);
  CLI11_PARSE(app, argc, argv);

  try {
    // A resumed run reads its own config.yaml: the run goes on with the settings it started with.
    const std::string base = resume_dir.empty() ? "" : resume_dir + "/config.yaml";
    const auto rc = masa::config::loadRunConfig(configs, overrides, base);
    masa::learner::LearnerOptions opt;
    opt.url = url;
    opt.run_id = run_id;
    if (!resume_dir.empty()) {
      opt.resume = true;
      opt.run_dir = resume_dir;
    } else {
      opt.run_dir = !run_dir.empty() ? run_dir
                                     : "runs/" + rc.task + "_" + masa::model::methodName(rc.method) + "_" +
                                           std::to_string(rc.seed) + "_" + timestamp();
    }
    if (max_updates < 0) max_updates = rc.ppo.max_epochs;
    if (no_auth) {
      std::cerr << "masa_learner: WARNING: --no-auth: messages are neither signed nor checked; anyone who can "
                   "reach this network can feed this run rollouts\n";
    } else {
      std::filesystem::create_directories(opt.run_dir);
      if (key_file.empty()) key_file = (std::filesystem::path(opt.run_dir) / "run.key").string();
      opt.run_key = masa::transport::readOrCreateRunKey(key_file);
      std::cout << "masa_learner: messages authenticated with the run key " << key_file << " (key id "
                << opt.run_key->id() << ")" << std::endl;
    }

    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    masa::learner::Learner learner(rc, opt);
    std::cout << "masa_learner: run id " << learner.runId() << ", run dir " << learner.runDir() << ", version "
              << learner.version() << ", url '" << url << "'" << std::endl;
    // run() finishes the step in progress when a signal arrives, then checkpoints.
    learner.run(max_updates, &g_stop);
    std::cout << "masa_learner: stopped after " << learner.updates() << " updates; checkpoint written" << std::endl;
    // What became of the actors' rollout chunks, by reason (lost: never arrived).
    const auto& drops = learner.dropStats();
    std::cout << "masa_learner: rollout chunks accepted " << drops[masa::learner::DropReason::kAccepted];
    for (int r = 1; r < masa::learner::kNumDropReasons; ++r) {
      const auto reason = static_cast<masa::learner::DropReason>(r);
      if (drops[reason] > 0) std::cout << ", " << masa::learner::dropReasonName(reason) << " " << drops[reason];
    }
    std::cout << std::endl;
    std::cout << "masa_learner: updates on batches short of lost environments " << learner.shortBatches() << std::endl;
    std::cout << "masa_learner: MLP chunk width: " << learner.model().chunkWidthSummary() << std::endl;
    std::cout << "masa_learner: other messages rejected before decoding: " << learner.transport().rejectSummary()
              << std::endl;
  } catch (const std::exception& e) {
    std::cerr << "masa_learner: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
