// masa_learner: the training process. Actors (masa_actor) send rollouts; this runs PPO and
// broadcasts parameters.
//   masa_learner --set task=trifinger_lift --set method=masa
//   masa_learner --resume runs/trifinger_lift_masa_0_20260101-120000
// Every message is authenticated with the run key (--key-file, default RUN_DIR/run.key, made when
// missing); --no-auth turns that off. In a signed run (--roster RUN_DIR/roster --signing-key
// RUN_DIR/keys/learner0.key, made by masa_roster), the learner signs with its own key and believes
// only the roster's actors on their own channels (common/transport/message_sign.hpp).
// In an MPI job (mpirun, srun) it signs by default, with a key made in memory: every process of
// the job makes its own and the public keys are gathered over MPI (common/transport/job_roster.hpp);
// --key-file uses the run key instead, --no-auth nothing.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <memory>
#include <csignal>
#include <exception>
#include <filesystem>
#include <fstream>
#include <optional>
#include <iostream>
#include <string>
#include <vector>

#include "common/core/build_info.hpp"
#include "common/config/batch_shape.hpp"
#include "common/config/run_config.hpp"
#include "common/model/method.hpp"
#include "common/cluster/job_plan.hpp"
#include "common/cluster/mpi_job.hpp"
#include "common/transport/job_roster.hpp"
#include "common/transport/lcm_url.hpp"
#include "common/transport/run_key.hpp"
#include "learner/intake/drop_reason.hpp"
#include "learner/learner.hpp"
#include "learner/run_dir/run_directory.hpp"
#include "learner/algorithms/algorithm_catalog.hpp"

namespace {

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");

void onSignal(int) { g_stop.store(true); }

// RUN_DIR/job_roster, whole or not at all (written under a temporary name, then renamed).
void writeJobRoster(const std::string& run_dir, const masa::transport::Roster& roster) {
  const std::filesystem::path path = std::filesystem::path(run_dir) / "job_roster";
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << roster.format();
    if (!out.flush()) throw std::runtime_error(tmp.string() + ": cannot write the job's roster");
  }
  std::filesystem::permissions(tmp, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                                        std::filesystem::perms::group_read | std::filesystem::perms::others_read);
  std::filesystem::rename(tmp, path);
}

// How this learner authenticates (docs/reliability.md): a roster and its own key (a signed run),
// the MPI job's keys made in memory (job_keys), no authentication, or the run key (lead rank: read
// or made in the run directory; the other ranks get rank 0's over MPI afterwards).
void chooseAuthentication(masa::learner::LearnerOptions& opt, const std::string& roster_file,
                          const std::string& signing_key, std::string key_file, bool no_auth,
                          const masa::transport::SignedMode* job_keys, bool job, bool lead) {
  const bool signed_job = job_keys != nullptr;
  if (!roster_file.empty()) {
    if (job) throw std::runtime_error("--roster: an MPI job signs with keys its processes make in memory and gathers "
                                      "their public keys over MPI; leave out --roster and --signing-key");
    opt.signed_mode = masa::transport::loadSignedMode(roster_file, signing_key, {masa::transport::Role::kLearner, 0});
    std::cout << "masa_learner: messages signed with " << signing_key << " ("
              << masa::integrity::keyFingerprint(opt.signed_mode->signer->publicKey()) << "), senders checked against the roster "
              << roster_file << " (" << opt.signed_mode->roster->entries().size() << " senders)" << std::endl;
  } else if (signed_job) {
    opt.signed_mode = *job_keys;
    if (lead)
      std::cout << "masa_learner: messages signed with a key made in memory ("
                << masa::integrity::keyFingerprint(opt.signed_mode->signer->publicKey())
                << "), senders checked against the roster of the MPI job (" << opt.signed_mode->roster->entries().size()
                << " senders)" << std::endl;
  } else if (no_auth) {
    std::cerr << "masa_learner: WARNING: --no-auth: messages are neither signed nor checked; anyone who can "
                 "reach this network can feed this run rollouts\n";
  } else if (lead) {
    std::filesystem::create_directories(opt.run_dir);
    if (key_file.empty()) key_file = (std::filesystem::path(opt.run_dir) / "run.key").string();
    opt.run_key = masa::transport::readOrCreateRunKey(key_file);
    std::cout << "masa_learner: messages authenticated with the run key " << key_file << " (key id "
              << opt.run_key->id() << ")" << std::endl;
  }
}

// What the learner says when it stops: chunks by drop reason, short batches, parameter repeats, the
// MLP chunk widths, and the messages refused before decoding on each transport.
void printClosingReport(masa::learner::Learner& learner, const std::string& who, bool lead) {
  // What became of the actors' rollout chunks, by reason (lost: never arrived).
  const auto& drops = learner.dropStats();
  std::cout << who << ": rollout chunks accepted " << drops[masa::learner::DropReason::kAccepted];
  for (int r = 1; r < masa::learner::kNumDropReasons; ++r) {
    const auto reason = static_cast<masa::learner::DropReason>(r);
    if (drops[reason] > 0) std::cout << ", " << masa::learner::dropReasonName(reason) << " " << drops[reason];
  }
  std::cout << std::endl;
  std::cout << who << ": updates on batches short of lost environments " << learner.shortBatches() << std::endl;
  if (lead)
    std::cout << who << ": parameter broadcasts repeated for actors that had not acknowledged them "
              << learner.unacknowledgedRepeats() << "; actors that acknowledged parameters "
              << learner.acknowledgingActors() << std::endl;
  if (const std::string kernels = learner.algorithm().kernelSummary(); !kernels.empty())
    std::cout << who << ": MLP chunk width: " << kernels << std::endl;
  std::cout << who << ": other messages rejected before decoding: " << learner.transport().rejectSummary();
  // Rank 0 of several hears the actors' heartbeats on the parameters' URL, another transport.
  if (&learner.publisher() != &learner.transport())
    std::cout << "; on the parameters' URL " << learner.publisher().rejectSummary();
  std::cout << std::endl;
}

}  // namespace

int main(int argc, char** argv) {
  // Started by mpirun or srun: one of the job's learner ranks (docs/scaling.md). MPI first, so that
  // a rank that fails below still ends the whole job instead of leaving it waiting.
  std::unique_ptr<masa::cluster::MpiJob> job;
  try {
    if (masa::cluster::launchedByMpi()) job = std::make_unique<masa::cluster::MpiJob>(masa::cluster::Role::kLearner);
  } catch (const std::exception& e) {
    std::cerr << "masa_learner: " << e.what() << "\n";
    return 2;
  }
  CLI::App app{"masa learner: multi-agent PPO fed by actors over LCM"};
  app.set_version_flag("--version", masa::buildCommit());
  std::vector<std::string> overrides;
  std::string configs = masa::config::defaultConfigsDir();
  std::string run_dir, resume_dir, url;
  int64_t run_id = 0;
  int64_t max_updates = -1;
  app.add_option("--set", overrides, "key.path=value override (repeatable), e.g. --set ppo.horizon=8");
  app.add_option("--configs", configs, "configs directory (defaults.yaml, tasks/, specs/)");
  app.add_option("--run-dir", run_dir, "run directory (default runs/<task>_<method>_<seed>_<time>)");
  app.add_option("--resume", resume_dir, "continue the run in this directory from its checkpoint.bin, with its config.yaml (--set still applies)");
  // The same default as masa_actor: loopback multicast with a receive buffer large enough for chunks.
  url = masa::transport::loopbackUrl();
  app.add_option("--url", url, "LCM provider URL")->capture_default_str();
  app.add_option("--run-id", run_id, "run id actors must carry (default: random, or the checkpoint's)");
  app.add_option("--max-updates", max_updates, "stop after this many updates in total (default ppo.max_updates, or sac.env_steps in rounds off-policy)")
      ->check(CLI::NonNegativeNumber);
  std::string key_file;
  bool no_auth = false;
  auto* key_opt = app.add_option("--key-file", key_file,
                                 "the run key every message is authenticated with (default: RUN_DIR/run.key, made "
                                 "when missing; give the actors the same file). In an MPI job: authenticate with "
                                 "this run key instead of signing");
  auto* no_auth_opt = app.add_flag("--no-auth", no_auth, "send and accept messages without authentication (anyone on the network can "
                                     "then feed this run rollouts)")->excludes(key_opt);
  std::string roster_file, signing_key;
  auto* roster_opt = app.add_option("--roster", roster_file,
                                    "a signed run: the run's roster (public keys and channels per sender, masa_roster)")
                         ->excludes(key_opt)->excludes(no_auth_opt);
  app.add_option("--signing-key", signing_key, "a signed run: this learner's private key file (mode 0600)")
      ->needs(roster_opt);
  roster_opt->needs("--signing-key");
  int rank_check_every = 10;
  app.add_option("--rank-check-every", rank_check_every,
                 "data-parallel ranks compare parameter hashes every this many updates")
      ->capture_default_str()->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  masa::cluster::Communicator* ranks = job ? &job->learners() : nullptr;
  const bool lead = !ranks || ranks->rank() == 0;
  const std::string who = ranks ? "masa_learner " + ranks->describe() : "masa_learner";

  try {
    // A resumed run reads its own config.yaml: the run goes on with the settings it started with.
    const std::string base = resume_dir.empty() ? "" : resume_dir + "/config.yaml";
    const auto rc = masa::config::loadRunConfig(configs, overrides, base);
    masa::config::checkBatchShape(rc, ranks ? ranks->size() : 1);
    masa::learner::LearnerOptions opt;
    opt.url = url;
    opt.run_id = run_id;
    opt.ranks = ranks;
    opt.rank_check_every = rank_check_every;
    opt.make_algorithm = masa::learner::makeAlgorithm;
    opt.verbose = lead;
    if (ranks) opt.rollout_url = masa::transport::rankRolloutUrl(url, ranks->rank(), ranks->size());
    if (!resume_dir.empty()) {
      opt.resume = true;
      opt.run_dir = resume_dir;
    } else {
      opt.run_dir = !run_dir.empty() ? run_dir
                                     : masa::learner::defaultRunDir(rc.task + "_" + masa::model::methodName(rc.method),
                                                                    rc.seed);
    }
    if (max_updates < 0) max_updates = rc.rollout.max_updates;
    // Collective over the whole job, whatever the authentication: the actors cannot know it before
    // the plan, and a collective every process of the job enters must not depend on it.
    std::optional<masa::transport::SignedMode> job_keys;
    if (job)
      job_keys = masa::transport::jobSignedMode(
          {masa::transport::Role::kLearner, static_cast<uint32_t>(ranks->rank())},
          [&](const std::vector<uint8_t>& mine) { return job->gatherFromEveryProcess(mine); });
    const bool signed_job = job && !no_auth && key_file.empty();
    if (ranks) {
      // Rank 0's run directory (its default has rank 0's timestamp) for every rank.
      std::vector<uint8_t> dir(opt.run_dir.begin(), opt.run_dir.end());
      ranks->broadcast(dir, 0);
      opt.run_dir.assign(dir.begin(), dir.end());
    }
    chooseAuthentication(opt, roster_file, signing_key, key_file, no_auth, signed_job ? &*job_keys : nullptr,
                         job != nullptr, lead);
    // Each rank takes rollouts only from the actors that report to it (actor i: rank i mod ranks).
    if (ranks && opt.signed_mode)
      opt.signed_mode->rollout_share = {static_cast<uint32_t>(ranks->rank()), static_cast<uint32_t>(ranks->size())};
    if (ranks && !no_auth && !signed_job) {
      // Rank 0's key for the other ranks, over MPI: never on a command line or in a shared file.
      std::vector<uint8_t> key;
      if (lead) key.assign(opt.run_key->bytes.begin(), opt.run_key->bytes.end());
      ranks->broadcast(key, 0);
      masa::transport::RunKey k;
      if (key.size() != k.bytes.size()) throw std::runtime_error("run key from rank 0 has " + std::to_string(key.size()) + " bytes");
      std::copy(key.begin(), key.end(), k.bytes.begin());
      opt.run_key = k;
    }

    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    masa::learner::Learner learner(rc, opt);
    std::cout << who << ": run id " << learner.runId() << ", run dir " << learner.runDir() << ", version "
              << learner.version() << ", url '" << url << "'"
              << (ranks ? ", rollouts on '" + opt.rollout_url + "'" : std::string()) << std::endl;
    if (job) {
      // The run for every actor of the job: its id, the parameters' URL, the key.
      masa::cluster::JobPlan plan;
      plan.run_id = learner.runId();
      plan.url = url;
      if (opt.run_key) plan.key = opt.run_key->bytes;
      plan.signed_job = signed_job;
      // The job's roster, public, for a watcher (masa_lcm_probe --roster RUN_DIR/job_roster); the
      // job itself never reads it. A new job writes its own (new keys).
      if (lead && signed_job) writeJobRoster(learner.runDir(), *opt.signed_mode->roster);
      std::vector<uint8_t> bytes = lead ? plan.encode() : std::vector<uint8_t>{};
      job->shareFromLearnerZero(bytes);
    }
    // run() finishes the step in progress when a signal arrives, then checkpoints.
    learner.run(max_updates, &g_stop);
    // Ranks stopped because one heard no rollout data: its actors may be alive but hung, and would
    // never join the end-of-training barrier; the learner ranks meet alone (rank 0's checkpoint is
    // then written) and end the job below.
    const bool cut_short = learner.silentRanksAtStop() > 0;
    if (job && !cut_short) job->finishTraining();  // the job's actors stop
    if (job && cut_short) {
      double here = 1;
      ranks->sum(&here, 1);
    }
    std::cout << who << ": stopped after " << learner.updates() << " updates"
              << (lead ? "; checkpoint written" : "") << std::endl;
    printClosingReport(learner, who, lead);
    // Stopped because a rank heard nothing: not the run's end, so not success for a job script,
    // and the job's actors end with it (MPI_Abort), hung or not.
    if (cut_short) {
      std::cerr << who << ": ending the job (exit 3): a learner rank heard no rollout data" << std::endl;
      if (job) job->abort(3);
      return 3;
    }
  } catch (const std::exception& e) {
    std::cerr << who << ": " << e.what() << "\n";
    // A rank that stops alone would leave the others waiting in a collective: end the job.
    if (job) job->abort(2);
    return 2;
  }
  return 0;
}
