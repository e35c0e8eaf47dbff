#include "actors/actor.hpp"

#include <omp.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "common/model/diag_gaussian.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "common/transport/channels.hpp"
#include "masa/lcmt_actor_heartbeat.hpp"
#include "tasks/tasks.hpp"

namespace masa::actor {
namespace {

double nowSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

Rng envRng(std::uint64_t seed, int actor_id, int env) {
  // seed_seq mixes all three, so neighbouring (actor, env) pairs get unrelated streams.
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(actor_id), static_cast<std::uint32_t>(env), 0x6d617361u};
  return Rng(seq);
}

// A positive incarnation that a restart of the same actor (a new process, a later clock) will not
// repeat: the clock's nanoseconds and the process id, mixed (splitmix64's finalizer).
int64_t incarnationFromClock() {
  uint64_t x = static_cast<uint64_t>(std::chrono::system_clock::now().time_since_epoch().count());
  x ^= static_cast<uint64_t>(::getpid()) << 40;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return static_cast<int64_t>(x & 0x7fffffffffffffffULL) | 1;
}

// Runs f with the calling thread's OpenMP team size at 1, so the network's GEMM stays serial.
template <class F>
void singleThreaded(F&& f) {
  const int prev = omp_get_max_threads();
  omp_set_num_threads(1);
  f();
  omp_set_num_threads(prev);
}

}  // namespace

Actor::Actor(const config::RunConfig& config, ActorOptions options, transport::MessageBus* transport)
    : config_(config),
      options_(std::move(options)),
      num_envs_(options_.num_envs),
      horizon_(config.rollout.horizon),
      transport_(transport),
      chunker_(options_.chunk_bytes) {
  if (num_envs_ <= 0) throw std::runtime_error("actor: num_envs must be positive, got " + std::to_string(num_envs_));
  if (horizon_ <= 0) throw std::runtime_error("actor: " + config.rollout.key("horizon") + " must be positive, got " + std::to_string(horizon_));
  if (options_.actor_id < 0) throw std::runtime_error("actor: actor_id must be >= 0");
  if (options_.threads <= 0) throw std::runtime_error("actor: threads must be positive");
  if (!(options_.drop_chunks_percent >= 0.0 && options_.drop_chunks_percent <= 100.0))
    throw std::runtime_error("actor: drop_chunks_percent must be in [0, 100]");
  incarnation_ = options_.incarnation != kIncarnationFromClock ? options_.incarnation : incarnationFromClock();
  drop_rng_.seed(options_.drop_seed);

  const auto spec = sym::SymmetrySpec::load(config_.spec_path);
  factory_ = std::make_unique<task::TaskFactory>(task::taskCatalog(), config_.task, spec, config_.env, config_.origin);
  envs_.reserve(num_envs_);
  rngs_.reserve(num_envs_);
  for (int e = 0; e < num_envs_; ++e) {
    envs_.push_back(factory_->create());
    rngs_.push_back(envRng(config_.seed, options_.actor_id, e));
  }
  obs_dim_ = envs_[0]->obsDim();
  act_dim_ = envs_[0]->actDim();
  const auto& terms = envs_[0]->rewardTermNames();
  num_terms_ = static_cast<int>(terms.size());

  behaviour_ = makeBehaviour(config_, spec);
  // Own initial parameters: used only with start_without_learner, and deterministic per seed.
  Rng init_rng = envRng(config_.seed, options_.actor_id, -1);
  behaviour_->initialize(init_rng);
  policy_param_count_ = behaviour_->policyParamCount();
  const int model_param_count = behaviour_->modelParamCount();
  params_check_ = std::make_unique<ParamsCheck>(ParamsExpectation{
      .run_id = options_.run_id, .task = config_.task, .method = model::methodName(config_.method),
      .policy_param_count = policy_param_count_, .model_param_count = model_param_count,
      .obs_dim = obs_dim_, .max_version_step = options_.max_version_step});
  if (options_.start_without_learner) version_ = 0;

  rollout_.allocate(num_envs_, horizon_, obs_dim_, act_dim_, terms);
  done_.assign(num_envs_, 0);
  final_obs_.assign(static_cast<std::size_t>(num_envs_) * obs_dim_, 0.0f);
  ep_return_.assign(num_envs_, 0.0f);
  ep_length_.assign(num_envs_, 0);
  ep_success_.assign(num_envs_, -1);
  ep_terms_.assign(static_cast<std::size_t>(num_envs_) * std::max(num_terms_, 1), 0.0f);
  log_std_.resize(act_dim_);
  pending_params_.resize(std::max(policy_param_count_, model_param_count));
  pending_mean_.resize(obs_dim_);
  pending_std_.resize(obs_dim_);

  for (int e = 0; e < num_envs_; ++e) envs_[e]->reset(rngs_[e]);

  if (!transport_) {
    owned_transport_ = makeTransport(options_.url.empty() ? transport::loopbackUrl() : options_.url);
    transport_ = owned_transport_.get();
  }
  const auto* lcm = dynamic_cast<const transport::Transport*>(transport_);  // null for an in-process bus
  if (!options_.rollout_url.empty() && (!lcm || options_.rollout_url != lcm->url()))
    rollout_transport_ = makeTransport(options_.rollout_url);
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) == 0) hostname_ = host;
  transport_->subscribe<masa::lcmt_policy_params>(
      transport::kPolicyChannel, [this](const masa::lcmt_policy_params& m) { onParams(m); });
}

Actor::~Actor() = default;

std::unique_ptr<transport::Transport> Actor::makeTransport(const std::string& url) const {
  if (options_.signed_mode) return std::make_unique<transport::Transport>(url, *options_.signed_mode);
  return std::make_unique<transport::Transport>(url, options_.run_key);
}

void Actor::onParams(const masa::lcmt_policy_params& m) {
  if (!params_check_->ofThisRun(m)) return;  // another run on the same network
  const int64_t newest = std::max(version_, pending_version_);
  // Checked before anything it says is believed, a repeat at our version too (docs/inputs.md gap 10:
  // a malformed message at our version used to count as the learner being alive).
  if (const auto why = params_check_->refusal(m, newest)) return rejectParams(m.version, *why);
  if (m.version == newest) {  // the learner's periodic repeat: it is alive, and agrees with us
    last_learner_s_ = nowSeconds();
    behind_in_a_row_ = 0;
    acknowledge_ = true;  // our acknowledgement may have been lost: the learner repeats until it hears one
    return;
  }
  const bool behind = m.version < newest;
  const int n = m.num_params;
  if (behind) {
    // Usually a late copy of older parameters: ignored. But when valid parameters below ours keep
    // coming, with none at our version in between, ours were never the learner's: on a network
    // without authentication a forged or corrupted message with a plausible version got in, and
    // the learner drops every chunk acted with it (future_version). Taking the learner's version
    // back ends that; a replay that pushes us back costs stale chunks until the next update.
    if (++behind_in_a_row_ < options_.behind_repeats_to_take_back) return;
    if (pending_version_ != m.version)  // once: the repeats until the next rollout take it again
      std::fprintf(stderr,
                   "masa_actor %d: taking parameters version %lld back from %lld: %d valid messages in a row below "
                   "this actor's version, none at it (was %lld forged or corrupted? use the run key)\n",
                   options_.actor_id, static_cast<long long>(m.version), static_cast<long long>(newest),
                   behind_in_a_row_, static_cast<long long>(newest));
  }
  behind_in_a_row_ = 0;
  std::copy(m.params.begin(), m.params.end(), pending_params_.begin());
  pending_count_ = n;
  if (m.obs_dim > 0) {
    std::copy(m.obs_mean.begin(), m.obs_mean.end(), pending_mean_.begin());
    std::copy(m.obs_std.begin(), m.obs_std.end(), pending_std_.begin());
  }
  // How long the learner took to answer a rollout: the wait after the next one adapts to it.
  if (const auto delay = lag_window_.answer(m.version, nowSeconds())) await_budget_.observeAnswer(*delay);
  pending_version_ = m.version;
  pending_has_norm_ = m.obs_dim > 0;
  last_learner_s_ = nowSeconds();
  acknowledge_ = true;
}

void Actor::rejectParams(int64_t version, const std::string& why) {
  ++params_rejected_;
  ++rejects_since_warning_;
  const double now = nowSeconds();
  if (now - last_reject_warning_s_ < options_.reject_warning_interval_s) return;
  std::fprintf(stderr, "masa_actor %d: ignoring parameters version %lld: %s (%lld rejected since the last such line)\n",
               options_.actor_id, static_cast<long long>(version), why.c_str(),
               static_cast<long long>(rejects_since_warning_));
  last_reject_warning_s_ = now;
  rejects_since_warning_ = 0;
}

void Actor::swapInPending() {
  if (pending_version_ < 0) return;
  behaviour_->set(pending_params_.data(), pending_count_, pending_has_norm_ ? pending_mean_.data() : nullptr,
                  pending_has_norm_ ? pending_std_.data() : nullptr);
  version_ = pending_version_;
  pending_version_ = -1;
}

bool Actor::pollParams(int timeout_ms) {
  if (!hasParams() && pending_version_ < 0) transport_->handleTimeout(timeout_ms);
  transport_->drain();
  if (!hasParams()) swapInPending();
  maybeHeartbeat();
  return hasParams();
}

void Actor::publishHeartbeat() {
  const double now = nowSeconds();
  masa::lcmt_actor_heartbeat hb;
  hb.run_id = options_.run_id;
  hb.actor_id = options_.actor_id;
  hb.utime = transport::wallClockMicros();
  hb.hostname = hostname_;
  hb.num_envs = num_envs_;
  const double dt = now - last_heartbeat_s_;
  hb.steps_per_second = (dt > 0.0 && dt < 1e9) ? static_cast<float>(steps_since_heartbeat_ / dt) : 0.0f;
  hb.policy_version = version_;
  hb.rollouts_sent = rollouts_sent_;
  hb.params_version = std::max(version_, pending_version_);
  // On the parameters' URL: the learner that publishes parameters (rank 0 of a data-parallel job)
  // takes them as acknowledgements; with one URL for both, this is the rollouts' URL too.
  transport_->publish(transport::kHeartbeatChannel, hb);
  last_heartbeat_s_ = now;
  steps_since_heartbeat_ = 0;
  acknowledge_ = false;
}

void Actor::maybeHeartbeat() {
  // At once when parameters came: the learner repeats them until this actor acknowledges them.
  if (acknowledge_ || nowSeconds() - last_heartbeat_s_ >= options_.heartbeat_interval_s) publishHeartbeat();
}

namespace {
void keepRecent(std::vector<double>& times, double seconds) {
  if (times.size() >= Actor::kTimesKept) times.erase(times.begin(), times.begin() + Actor::kTimesKept / 2);
  times.push_back(seconds);
}
}  // namespace

double Actor::awaitLimitSeconds() const {
  return await_budget_.limitSeconds();
}

void Actor::awaitNewerParams() {
  const double began = nowSeconds();
  // With max_policy_lag 0 the parameters that answer the rollout just sent; with lag L those
  // that answer the rollout L before it (PolicyLagWindow), so rollouts and updates overlap.
  const int64_t needed = lag_window_.neededVersion();
  // The learner evaluates its policy after publishing every runner.eval_every-th version, before it
  // makes the next: those parameters come late by the evaluation, and a wait of the usual length
  // would send a rollout too old to use. Waits for them are as long as the bound allows.
  const int64_t eval_every = config_.runner.eval_every;
  const bool after_evaluation = eval_every > 0 && needed > 1 && (needed - 1) % eval_every == 0;
  const double deadline = began + std::max(awaitLimitSeconds(), after_evaluation ? options_.await_params_max_s : 0.0);
  for (double now = nowSeconds(); std::max(pending_version_, version_) < needed && now < deadline && !stopRequested();
       now = nowSeconds()) {
    // Short slices: the stop flag and heartbeats are served while waiting.
    transport_->handleTimeout(static_cast<int>(std::min(100.0, std::ceil((deadline - now) * 1000.0))));
    transport_->drain();
    maybeHeartbeat();
  }
  if (std::max(pending_version_, version_) < needed && !stopRequested()) await_budget_.observeTimeout();
  keepRecent(await_s_, nowSeconds() - began);
}

bool Actor::collectAndPublish() {
  const double began = nowSeconds();
  swapInPending();  // the only place parameters change
  if (!hasParams()) throw std::logic_error("actor: collectAndPublish before any parameters");
  const int64_t acting_version = version_;
  const int E = num_envs_;
  rollout_.clearEvents();
  behaviour_->logStd(log_std_);
  rollout_.setLogStd(log_std_.data());

  for (int e = 0; e < E; ++e) envs_[e]->observe(rollout_.obsAt(0, e));
  const int threads = std::min(options_.threads, E);
  for (int t = 0; t < horizon_; ++t) {
    // Step t's observations, actions and means are contiguous obs_dim x E / act_dim x E blocks.
    Eigen::Map<const Mat<float>> obs(rollout_.obsAt(t, 0), obs_dim_, E);
    float* log_prob = rollout_.log_prob.data() + rollout_.step(t, 0);
    singleThreaded([&] {  // the whole block's actions at once, each environment's noise its own
      behaviour_->act(obs, rngs_, Eigen::Map<Mat<float>>(rollout_.actionAt(t, 0), act_dim_, E),
                      Eigen::Map<Mat<float>>(rollout_.meanAt(t, 0), act_dim_, E), log_prob);
    });
    float* reward = rollout_.reward.data() + rollout_.step(t, 0);
    uint8_t* term = rollout_.terminated.data() + rollout_.step(t, 0);
    uint8_t* trunc = rollout_.truncated.data() + rollout_.step(t, 0);

#pragma omp parallel for num_threads(threads) schedule(static)
    for (int e = 0; e < E; ++e) {
      auto& env = *envs_[e];
      const task::StepOutcome out = env.step(rollout_.actionAt(t, e));
      reward[e] = static_cast<float>(out.reward);
      term[e] = out.terminated ? 1 : 0;
      trunc[e] = out.truncated ? 1 : 0;
      const bool done = out.terminated || out.truncated;
      done_[e] = done ? 1 : 0;
      if (done) {
        if (out.truncated) env.observe(final_obs_.data() + static_cast<std::size_t>(e) * obs_dim_);
        const auto& st = env.episode();
        ep_return_[e] = static_cast<float>(st.ret);
        ep_length_[e] = st.length;
        ep_success_[e] = st.has_success ? (st.success ? 1 : 0) : -1;
        for (int k = 0; k < num_terms_; ++k)
          ep_terms_[static_cast<std::size_t>(e) * num_terms_ + k] = static_cast<float>(st.term_sums[k]);
        env.reset(rngs_[e]);
      }
      env.observe(rollout_.obsAt(t + 1, e));
    }
    // Events in ascending (t, e) order, as Rollout requires.
    for (int e = 0; e < E; ++e) {
      if (!done_[e]) continue;
      if (trunc[e]) rollout_.addFinal(t, e, final_obs_.data() + static_cast<std::size_t>(e) * obs_dim_);
      rollout_.addEpisode(e, ep_return_[e], ep_length_[e], ep_success_[e],
                          num_terms_ ? ep_terms_.data() + static_cast<std::size_t>(e) * num_terms_ : nullptr);
    }
    steps_since_heartbeat_ += E;
    if (options_.after_step) options_.after_step(rollouts_sent_, t);
    transport_->drain();  // parameters go to the pending buffer; nothing changes mid-rollout
    maybeHeartbeat();
    if (stopRequested()) return false;
  }

  RolloutIdentity id;
  id.run_id = options_.run_id;
  id.actor_id = options_.actor_id;
  id.incarnation = incarnation_;
  id.rollout_seq = rollouts_sent_;
  id.policy_version = acting_version;
  std::uniform_real_distribution<double> percent(0.0, 100.0);
  for (const auto& chunk : chunker_.split(rollout_, id)) {
    if (options_.drop_chunks_percent > 0.0 && percent(drop_rng_) < options_.drop_chunks_percent) {
      ++chunks_dropped_;  // fault injection: as if the network had lost it
      continue;
    }
    sender().publish(transport::kRolloutChannel, chunk);
    ++chunks_published_;
  }
  ++rollouts_sent_;
  lag_window_.sent(acting_version, nowSeconds());
  keepRecent(collect_s_, nowSeconds() - began);
  return true;
}

bool Actor::awaitLearnerIfSilent() {
  const double pause = options_.learner_silence_pause_s, exit_after = options_.learner_silence_exit_s;
  if (pause <= 0 || nowSeconds() - last_learner_s_ < pause) return true;
  std::fprintf(stderr, "masa_actor %d: nothing from the learner for %.0f s; not publishing until it is back%s\n",
               options_.actor_id, nowSeconds() - last_learner_s_,
               exit_after > 0 ? (", exiting after " + std::to_string(static_cast<int>(exit_after)) + " s").c_str() : "");
  while (!stopRequested() && nowSeconds() - last_learner_s_ >= pause) {
    if (exit_after > 0 && nowSeconds() - last_learner_s_ >= exit_after) {
      std::fprintf(stderr, "masa_actor %d: nothing from the learner for %.0f s; exiting\n", options_.actor_id,
                   nowSeconds() - last_learner_s_);
      return false;
    }
    transport_->handleTimeout(100);
    transport_->drain();
    maybeHeartbeat();
  }
  if (!stopRequested()) std::fprintf(stderr, "masa_actor %d: the learner is back\n", options_.actor_id);
  return !stopRequested();
}

int64_t Actor::run() {
  publishHeartbeat();  // announce at start, before any parameters
  while (!stopRequested() && !pollParams(100)) {
  }
  last_learner_s_ = std::max(last_learner_s_, nowSeconds());
  while (!stopRequested() && (options_.max_rollouts < 0 || rollouts_sent_ < options_.max_rollouts)) {
    if (!awaitLearnerIfSilent()) break;
    if (!collectAndPublish()) break;
    if (options_.max_rollouts < 0 || rollouts_sent_ < options_.max_rollouts) awaitNewerParams();
  }
  publishHeartbeat();  // final state: version acted with, rollouts sent
  return rollouts_sent_;
}

}  // namespace masa::actor
