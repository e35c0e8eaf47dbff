// An actor process's worker: E task instances stepped together, acting with the newest policy
// received from the learner, and streaming each T-step rollout as LCM chunks. How it acts is its
// behaviour (behaviour.hpp): PPO's Gaussian, or with learner: off_policy the SAC or TD3 policy;
// the rollouts are the same either way.
//
// Determinism: environment e of actor a draws resets and action noise from its own Rng, seeded
// from (run seed, a, e), so a run is reproducible for any thread count. Parameters received while
// a rollout is being collected wait in a pending buffer and are swapped in only between rollouts,
// so every chunk of a rollout was produced by the one version it names.
//
// Threading: the network runs single-threaded (its 2-thread GEMM collapses when cores are
// shared by several actors); OpenMP is used only over environments.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/config/run_config.hpp"
#include "common/sim/registry.hpp"
#include "actors/await_budget.hpp"
#include "actors/behaviour.hpp"
#include "actors/params_check.hpp"
#include "actors/policy_lag_window.hpp"
#include "common/rollout/rollout.hpp"
#include "actors/rollout_chunker.hpp"
#include "common/transport/message_bus.hpp"
#include "common/transport/transport.hpp"
#include "masa/lcmt_policy_params.hpp"

namespace masa::actor {

// ActorOptions::incarnation: pick one from the clock and the process id (see there).
inline constexpr int64_t kIncarnationFromClock = 0;

struct ActorOptions {
  int actor_id = 0;
  int num_envs = 1;
  int64_t run_id = 0;
  std::string url;               // "" -> transport::loopbackUrl(); ignored with an external transport
  // Where rollouts and heartbeats go, when not to `url`: its learner rank's own URL in a
  // data-parallel run (docs/scaling.md), while the parameters still come on `url`. "" = url.
  std::string rollout_url;
  // Authenticates every message (common/transport/message_auth.hpp): the learner's run key. None:
  // unsigned (--no-auth). Ignored with an external transport.
  std::optional<transport::RunKey> run_key;
  // A signed run instead (common/transport/message_sign.hpp): this actor's key and the run's roster.
  std::optional<transport::SignedMode> signed_mode;
  int64_t max_rollouts = -1;     // < 0: until stopped
  int threads = 1;               // OpenMP threads over environments
  bool start_without_learner = false;  // act with own initial parameters as version 0
  double heartbeat_interval_s = 1.0;
  int chunk_bytes = kDefaultChunkBytes;
  // This process's incarnation (lcmt_rollout_chunk.incarnation): an actor restarted with the same
  // id must differ from its previous process, so that the learner takes its rollouts, numbered from
  // 0 again, for a restart and not for replays. kIncarnationFromClock: mixed from the wall clock
  // and the process id. Tests fix it for bit-identical chunks; it changes no random draw.
  int64_t incarnation = kIncarnationFromClock;
  // Fault injection for tests, off by default: this percentage of chunks is counted and thrown
  // away instead of published, chosen by a generator seeded with drop_seed (reproducible).
  double drop_chunks_percent = 0.0;
  uint64_t drop_seed = 1;
  // After each rollout, wait for parameters newer than the ones it acted with. Without the wait a
  // fast actor collects rollouts the learner will drop as stale (with max_policy_lag 0, a third of
  // the data in a 2-actor run). Bounded, so that a batch still fills when another actor is dead or
  // a chunk was lost (at the cost of this wait). This long until the learner has answered once;
  // 0: never wait.
  double await_params_s = 1.0;
  // Then 1.5x the learner's recent answer time (from the end of a rollout to the next parameters),
  // between these bounds (AwaitBudget): a big batch's update outlasts await_params_s, and a fast
  // learner short of a lost chunk's environments should not stand still for it. The parameters that
  // follow the learner's evaluation (every runner.eval_every updates) come late by it: waited for
  // this long.
  double await_params_max_s = 10.0;
  double await_params_min_s = 0.02;
  // An actor whose learner is gone (no parameters, not even the learner's periodic repeat) stops
  // publishing after this long, says so, and exits after learner_silence_exit_s. 0: never.
  double learner_silence_pause_s = 30.0;
  double learner_silence_exit_s = 300.0;
  // Parameters are believed only as plausible steps: a version more than this far ahead of the
  // actor's (of 0 before the first) is rejected. No run makes a million updates; a forged or fuzzed
  // version (2^51) would otherwise make the actor ignore every real update after it.
  int64_t max_version_step = 1'000'000;
  // Valid parameters of a version below the actor's, this many in a row with none at its version,
  // are taken (the actor's version was not the learner's; see Actor::onParams).
  int behind_repeats_to_take_back = 3;
  // Rejected parameter messages are warned about at most once per this interval (the learner
  // repeats its parameters, so a mismatch would otherwise print a line per repetition).
  double reject_warning_interval_s = 5.0;
  const std::atomic<bool>* stop = nullptr;  // checked between steps (signal handlers set it)
  // Test hook: called after each step t of a rollout (rollout_index counts this actor's rollouts
  // from 0, as rollout_seq does), before incoming messages are handled.
  std::function<void(int64_t rollout_index, int t)> after_step;
};

class Actor {
 public:
  // Throws std::runtime_error / ConfigError on a bad configuration. With `transport` given (memq
  // tests share one in-process LCM; masa_train a transport::LocalBus), it is used instead of
  // opening options.url; it must outlive the actor.
  Actor(const config::RunConfig& config, ActorOptions options, transport::MessageBus* transport = nullptr);
  ~Actor();
  Actor(const Actor&) = delete;
  Actor& operator=(const Actor&) = delete;

  // Waits for parameters (unless start_without_learner), then collects and publishes rollouts
  // until stopped or max_rollouts. Returns the number of rollouts sent.
  int64_t run();

  // One rollout: swaps in pending parameters, collects T steps, publishes. Requires parameters.
  // Returns false when stopped midway (nothing published).
  bool collectAndPublish();
  // Handles incoming messages for up to timeout_ms; true once parameters are available.
  bool pollParams(int timeout_ms);

  bool hasParams() const { return version_ >= 0; }
  int64_t policyVersion() const { return version_; }
  int64_t rolloutsSent() const { return rollouts_sent_; }
  int64_t incarnation() const { return incarnation_; }
  int64_t chunksPublished() const { return chunks_published_; }
  int64_t chunksDropped() const { return chunks_dropped_; }  // by drop_chunks_percent
  int64_t paramsRejected() const { return params_rejected_; }
  // Seconds each recent rollout took to collect and publish, and each wait after it for the
  // parameters the next one needed (the last kTimesKept of each): beside the learner's "learn /
  // waited" they say which side of a pipeline waits for which (docs/scaling.md).
  static constexpr std::size_t kTimesKept = 1024;
  const std::vector<double>& collectSeconds() const { return collect_s_; }
  const std::vector<double>& awaitSeconds() const { return await_s_; }
  const transport::MessageBus& transport() const { return *transport_; }
  const rollout::Rollout& lastRollout() const { return rollout_; }
  int numEnvs() const { return num_envs_; }
  // What the actor acts with (gaussian_behaviour.hpp or squashed_behaviour.hpp).
  Behaviour& behaviour() { return *behaviour_; }
  void publishHeartbeat();

  // The environments between two rollouts (actors/actor_environments.cpp): each task's state and
  // each environment's generator. An actor of the same run config that loads them collects the
  // same rollouts as this one would have (masa_train saves them beside the learner's checkpoint).
  // Loading throws, naming what does not fit: another task, another number of environments, a
  // file cut short; nothing is changed then.
  void saveEnvironments(std::ostream& out) const;
  void loadEnvironments(std::istream& in);

 private:
  void onParams(const masa::lcmt_policy_params& msg);
  std::unique_ptr<transport::Transport> makeTransport(const std::string& url) const;
  void rejectParams(int64_t version, const std::string& why);
  void swapInPending();
  bool stopRequested() const { return options_.stop && options_.stop->load(std::memory_order_relaxed); }
  void maybeHeartbeat();
  void awaitNewerParams();  // see ActorOptions::await_params_s
  double awaitLimitSeconds() const;
  // Before a rollout: true to go on; waits while the learner is silent, false when it is gone.
  bool awaitLearnerIfSilent();

  config::RunConfig config_;
  ActorOptions options_;
  int num_envs_;
  int horizon_;
  std::unique_ptr<transport::MessageBus> owned_transport_;
  transport::MessageBus* transport_;
  std::unique_ptr<transport::MessageBus> rollout_transport_;  // options.rollout_url's, when it differs
  transport::MessageBus& sender() { return rollout_transport_ ? *rollout_transport_ : *transport_; }
  std::unique_ptr<task::TaskFactory> factory_;
  std::vector<std::unique_ptr<task::Task>> envs_;
  std::vector<Rng> rngs_;
  std::unique_ptr<Behaviour> behaviour_;
  int policy_param_count_ = 0;  // the policy + log-std prefix of the flat parameters
  std::unique_ptr<ParamsCheck> params_check_;  // made once the model's sizes are known
  rollout::Rollout rollout_;
  RolloutChunker chunker_;
  int obs_dim_, act_dim_, num_terms_;

  // Per-environment scratch of one step, filled in parallel and recorded in env order after it.
  std::vector<int8_t> done_;
  std::vector<float> final_obs_;
  std::vector<float> ep_return_;
  std::vector<int32_t> ep_length_;
  std::vector<int8_t> ep_success_;
  std::vector<float> ep_terms_;
  Eigen::VectorXf log_std_;

  // Parameters received but not yet in use (version -1: none).
  int64_t version_ = -1;
  int64_t pending_version_ = -1;
  std::vector<float> pending_params_, pending_mean_, pending_std_;
  int pending_count_ = 0;
  bool pending_has_norm_ = false;
  // The rollouts sent and not yet answered, and what the next needs (config_ is declared above).
  PolicyLagWindow lag_window_{config_.rollout.max_policy_lag};
  double last_learner_s_ = 0;   // when the learner was last heard (new parameters or its repeat)
  // The wait for newer parameters, adapted to the learner's answer time (options_ is declared above).
  AwaitBudget await_budget_{options_.await_params_s, options_.await_params_max_s, options_.await_params_min_s};
  // Nothing of a rejected message is kept but these counts: it cannot change what comes after it.
  int64_t params_rejected_ = 0;
  std::vector<double> collect_s_, await_s_;
  int64_t rejects_since_warning_ = 0;
  int behind_in_a_row_ = 0;  // valid parameters below our version since the last at it
  // Parameters at or above our newest version came: the next heartbeat goes out at once, and
  // acknowledges them (lcmt_actor_heartbeat.params_version).
  bool acknowledge_ = false;
  double last_reject_warning_s_ = -1e300;

  int64_t rollouts_sent_ = 0;
  int64_t incarnation_ = 0;
  int64_t chunks_published_ = 0;
  int64_t chunks_dropped_ = 0;
  Rng drop_rng_;
  std::string hostname_;
  double last_heartbeat_s_ = -1e300;
  int64_t steps_since_heartbeat_ = 0;
};

}  // namespace masa::actor
