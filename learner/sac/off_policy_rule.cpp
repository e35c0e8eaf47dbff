#include "learner/sac/off_policy_rule.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <istream>
#include <ostream>
#include <stdexcept>

#include "common/core/binary_io.hpp"
#include "common/core/check.hpp"
#include "common/model/method.hpp"
#include "learner/run_dir/learning_curve.hpp"
#include "learner/sac/sac_critic_maps.hpp"
#include "learner/sac/sac_policy_file.hpp"
#include "learner/sac/trainer_factory.hpp"
#include "tasks/tasks.hpp"

namespace masa::sac {
namespace {
// Version 2 adds the streams' episodes (a version 1 state resumes with every stream's next
// stretch a new episode), version 3 the gradient steps forgiven while a thinned replay refilled.
constexpr char kMagic[8] = {'M', 'A', 'S', 'A', 'O', 'F', 'F', '3'};
constexpr char kMagicV2[8] = {'M', 'A', 'S', 'A', 'O', 'F', 'F', '2'};
constexpr char kMagicV1[8] = {'M', 'A', 'S', 'A', 'O', 'F', 'F', '1'};

// The task's goal relabeling, built only when it is asked for (a task instance loads its model).
std::unique_ptr<task::GoalRelabeling> goalRelabelingOf(const config::RunConfig& rc, const SacConfig& sc,
                                                       const sym::SymmetrySpec& spec) {
  if (!(sc.her_share > 0.0)) return nullptr;
  return task::TaskFactory(task::taskCatalog(), rc.task, spec, rc.env, rc.origin).create()->goalRelabeling();
}
}  // namespace

OffPolicyRule::OffPolicyRule(const config::RunConfig& rc, Rng& rng)
    : rc_(rc),
      sc_(readSacConfig(rc)),
      spec_(sym::SymmetrySpec::load(rc.spec_path)),
      policy_(spec_, policyShape(rc, sc_)),
      q_(spec_, twinQMaps(rc.method, spec_), sc_.q_hidden, rc.model.activation),
      q_target_(spec_, twinQMaps(rc.method, spec_), sc_.q_hidden, rc.model.activation),
      replay_(spec_.obsDim(), spec_.actDim(), sc_.buffer_size) {
  policy_.initialize(rng, static_cast<float>(rc.model.policy_last_layer_scale));
  q_.initialize(rng);
  q_target_.moveTowards(q_, 1.0f);
  trainer_ = makeTrainer(sc_, spec_, policy_, q_, q_target_);
  hindsight_ = std::make_unique<Hindsight>(rc, sc_, goalRelabelingOf(rc, sc_, spec_), spec_);
}

OffPolicyRule::~OffPolicyRule() = default;

learner::LearnFigures OffPolicyRule::learn(rollout::RolloutBuffer& batch, std::span<const int64_t> env_streams, Rng& rng) {
  return learn(batch.data(), env_streams, rng);
}

learner::LearnFigures OffPolicyRule::learn(const rollout::Rollout& b, std::span<const int64_t> env_streams, Rng& rng) {
  const int E = b.num_envs, T = b.horizon;
  MASA_CHECK(env_streams.empty() || static_cast<int>(env_streams.size()) == E,
             "off-policy learner: " << env_streams.size() << " stream ids for " << E << " environments");
  // Where each truncated step's pre-reset observation is (the list is in step order).
  std::vector<int> final_of(static_cast<std::size_t>(E) * T, -1);
  for (int i = 0; i < b.numFinal(); ++i) final_of[static_cast<std::size_t>(b.final_index[i])] = i;
  const std::size_t obs_bytes = sizeof(float) * static_cast<std::size_t>(b.obs_dim);
  for (int e = 0; e < E; ++e) {
    // The stream's episode goes on if this stretch starts where its last one ended.
    StreamTail* tail = nullptr;
    if (!env_streams.empty()) tail = &streams_[env_streams[e]];
    const bool continues = tail && !tail->last_obs.empty() && std::memcmp(tail->last_obs.data(), b.obsAt(0, e), obs_bytes) == 0;
    long long episode = continues ? tail->episode : next_episode_++;
    for (int t = 0; t < T; ++t) {
      const std::size_t s = b.step(t, e);
      const bool truncated = b.truncated[s] != 0, terminated = b.terminated[s] != 0;
      if (truncated && final_of[s] < 0) throw std::logic_error("off-policy learner: a truncation without its observation");
      const float* next = truncated ? b.finalObs(final_of[s]) : b.obsAt(t + 1, e);
      // The stretch's last step is cut: what follows it is in the next round's batch, if anywhere.
      replay_.add(b.obsAt(t, e), b.actionAt(t, e), b.reward[s], next, terminated, truncated || t == T - 1, episode);
      if (terminated || truncated) episode = next_episode_++;
    }
    if (tail) {
      tail->episode = episode;
      tail->last_obs.assign(b.obsAt(T, e), b.obsAt(T, e) + b.obs_dim);
    }
  }
  received_ += static_cast<long long>(E) * T;
  if (!fitted_ && received_ >= sc_.learning_starts) fitNormalizer();

  learner::LearnFigures out;
  round_means_ = SacStats{};
  round_steps_ = 0;
  round_relabeled_share_ = 0;
  if (!fitted_) return out;
  const long long owed = gradientStepsOwed(sc_, received_ - sc_.learning_starts + 1) - forgiven_;
  if (refilling()) {
    // Resumed from a compact state: no steps until the replay holds learning_starts again, and
    // none owed for the wait.
    forgiven_ += owed - trainer_->steps();
    return out;
  }
  SacStats sums;
  int n = 0;
  long long relabeled = 0;
  // The gradient steps on sac.threads threads (restored after): see configs/defaults.yaml.
  const int prev_threads = omp_get_max_threads();
  omp_set_num_threads(sc_.threads);
  for (; trainer_->steps() < owed; ++n) {
    relabeled += hindsight_->sample(replay_, sc_.batch_size, sc_.n_step, sc_.discount, rng, batch_);
    const SacStats s = trainer_->step(batch_, rng);
    sums.q_loss += s.q_loss;
    sums.actor_loss += s.actor_loss;
    sums.alpha_loss += s.alpha_loss;
    sums.symmetry_loss += s.symmetry_loss;
    sums.alpha += s.alpha;
    sums.mean_q += s.mean_q;
    sums.entropy += s.entropy;
  }
  omp_set_num_threads(prev_threads);
  round_steps_ = n;
  round_relabeled_share_ = n > 0 ? static_cast<double>(relabeled) / (static_cast<double>(n) * sc_.batch_size) : 0.0;
  if (n == 0) return out;
  for (double* v : {&sums.q_loss, &sums.actor_loss, &sums.alpha_loss, &sums.symmetry_loss, &sums.alpha, &sums.mean_q,
                    &sums.entropy})
    *v /= n;
  round_means_ = sums;
  out.actor_loss = sums.actor_loss;
  out.critic_loss = sums.q_loss;
  out.entropy = sums.entropy;
  out.sym_policy_loss = sums.symmetry_loss;
  return out;
}

std::string OffPolicyRule::progressFigures(const learner::LearnFigures&) const {
  return offPolicyProgressFigures(roundFigures());
}

std::string OffPolicyRule::curveScript(const std::string& title, const std::vector<std::string>& term_names,
                                       bool has_success) const {
  return learner::learningCurveScript(title + " (off-policy)", term_names, has_success, false);
}

std::optional<learner::SideStateFile> OffPolicyRule::sideState() const {
  return learner::SideStateFile{"off_policy_state.bin", {"masa off-policy learner state", "MASAOFF1"}};
}

void OffPolicyRule::loadCheckpointBody(std::istream& is, const std::string& source) {
  if (is.peek() != std::char_traits<char>::eof())
    throw std::runtime_error(source + ": an off-policy checkpoint holds nothing after the counters (corrupt checkpoint)");
}

std::string offPolicyProgressFigures(const std::vector<std::pair<std::string, double>>& figures) {
  auto figure = [&](const char* name) {
    for (const auto& [n, v] : figures)
      if (n == name) return v;
    return std::nan("");
  };
  char line[200];
  if (figure("warming_up") == 2) {
    std::snprintf(line, sizeof(line), "refilling the replay after a compact resume: %.0f transitions", figure("replay_size"));
  } else if (figure("warming_up") > 0) {
    std::snprintf(line, sizeof(line), "warming up: uniform random actions, replay %.0f", figure("replay_size"));
  } else {
    // TD3 has no temperature: alpha 0 and entropy NaN (off_policy_trainer.hpp).
    const double alpha = figure("alpha"), entropy = figure("entropy");
    char temperature[64] = "";
    if (!std::isnan(entropy)) std::snprintf(temperature, sizeof(temperature), "  alpha %.4f  entropy %.2f", alpha, entropy);
    std::snprintf(line, sizeof(line), "grad steps %.0f  q %.4f  actor %.4f%s  mean Q %.2f", figure("gradient_steps"),
                  figure("q_loss"), figure("actor_loss"), temperature, figure("mean_q"));
  }
  return line;
}



std::vector<std::pair<std::string, double>> OffPolicyRule::roundFigures() const {
  const SacStats& m = round_means_;
  const double none = std::nan("");  // a round without gradient steps (the warm-up) has no losses
  auto mean = [&](double v) { return round_steps_ > 0 ? v : none; };
  std::vector<std::pair<std::string, double>> figures = {{"gradient_steps", round_steps_},
          {"gradient_steps_total", static_cast<double>(trainer_->steps())},
          {"replay_size", static_cast<double>(replay_.size())},
          // 1: the uniform warm-up of a fresh run; 2: refilling after a compact resume.
          {"warming_up", !fitted_ ? 1.0 : refilling() ? 2.0 : 0.0},
          {"q_loss", mean(m.q_loss)},
          {"actor_loss", mean(m.actor_loss)},
          {"alpha_loss", mean(m.alpha_loss)},
          {"symmetry_loss", mean(m.symmetry_loss)},
          {"alpha", mean(m.alpha)},
          {"mean_q", mean(m.mean_q)},
          {"entropy", mean(m.entropy)}};
  // With hindsight relabeling: the share of the round's samples that got a goal achieved later.
  if (hindsight_->enabled()) figures.emplace_back("relabeled_share", mean(round_relabeled_share_));
  return figures;
}

void OffPolicyRule::fitNormalizer() {
  const int d = spec_.obsDim();
  std::vector<float> mean(d, 0.0f), std(d, 1.0f);  // the identity when observations are not normalized
  if (rc_.model.normalize_obs) {
    auto& norm = policy_.obsNormalizer();
    Mat<float> chunk;
    constexpr long long kChunk = 4096;
    for (long long at = 0; at < replay_.size(); at += kChunk) {
      const long long len = std::min(kChunk, replay_.size() - at);
      chunk.resize(d, len);
      for (long long j = 0; j < len; ++j) chunk.col(j) = Eigen::Map<const Eigen::VectorXf>(replay_.obsAt(at + j), d);
      norm.update(chunk);
    }
    for (int k = 0; k < d; ++k) {
      mean[k] = static_cast<float>(norm.mean()(k));
      std[k] = static_cast<float>(std::sqrt(norm.var()(k) + 1e-5));
    }
  }
  norm_mean_ = std::move(mean);
  norm_std_ = std::move(std);
  applyNormalizer();
  fitted_ = true;
}

void OffPolicyRule::applyNormalizer() {
  // Exactly the floats the actors are sent, so that learner and actors normalize alike.
  policy_.obsNormalizer().setMeanStd(norm_mean_.data(), norm_std_.data());
  policy_.setNormalizes(true);
}

void OffPolicyRule::fillPolicyMessage(masa::lcmt_policy_params& m) const {
  const auto& p = policy_.params().values();
  m.num_params = static_cast<int32_t>(p.size());
  m.params.assign(p.data(), p.data() + p.size());
  if (!fitted_) {  // warming up: the actors act uniformly at random
    m.obs_dim = 0;
    m.obs_mean.clear();
    m.obs_std.clear();
    return;
  }
  m.obs_dim = static_cast<int32_t>(norm_mean_.size());
  m.obs_mean = norm_mean_;
  m.obs_std = norm_std_;
}

model::ActorCritic<float>& OffPolicyRule::evaluationModel() {
  evaluation_model_ = toActorCritic(policy_, spec_, policyFileConfig(rc_, sc_, policy_.normalizes()).model);
  return *evaluation_model_;
}

void OffPolicyRule::savePolicyFile(const std::string& path) const { saveSacPolicyFile(path, rc_, sc_, policy_, spec_); }

void OffPolicyRule::save(std::ostream& os) const {
  os.write(kMagic, sizeof kMagic);
  io::writePod(os, received_);
  const int32_t fitted = fitted_ ? 1 : 0;
  io::writePod(os, fitted);
  if (fitted_) {
    os.write(reinterpret_cast<const char*>(norm_mean_.data()), static_cast<std::streamsize>(sizeof(float) * norm_mean_.size()));
    os.write(reinterpret_cast<const char*>(norm_std_.data()), static_cast<std::streamsize>(sizeof(float) * norm_std_.size()));
  }
  trainer_->save(os);  // the policy with its normalizer, Q, Q', the optimizers
  replay_.save(os, sc_.checkpoint_replay);
  io::writePod(os, forgiven_);
  io::writePod(os, next_episode_);
  io::writePod(os, static_cast<long long>(streams_.size()));
  for (const auto& [id, tail] : streams_) {
    io::writePod(os, id);
    io::writePod(os, tail.episode);
    io::writePod(os, static_cast<long long>(tail.last_obs.size()));
    os.write(reinterpret_cast<const char*>(tail.last_obs.data()), static_cast<std::streamsize>(sizeof(float) * tail.last_obs.size()));
  }
}

void OffPolicyRule::load(std::istream& is, const std::string& source_name) {
  char magic[8] = {};
  is.read(magic, sizeof magic);
  const bool v1 = is && std::string(magic, 8) == std::string(kMagicV1, 8);
  const bool v2 = is && std::string(magic, 8) == std::string(kMagicV2, 8);
  if (!is || (!v1 && !v2 && std::string(magic, 8) != std::string(kMagic, 8)))
    throw std::runtime_error(source_name + ": not an off-policy learner state");
  int32_t fitted = 0;
  if (!io::readPod(is, received_) || !io::readPod(is, fitted) || received_ < 0 || (fitted != 0 && fitted != 1))
    throw std::runtime_error(source_name + ": corrupt off-policy learner state");
  fitted_ = fitted == 1;
  if (fitted_) {
    const std::size_t d = static_cast<std::size_t>(spec_.obsDim());
    norm_mean_.resize(d);
    norm_std_.resize(d);
    is.read(reinterpret_cast<char*>(norm_mean_.data()), static_cast<std::streamsize>(sizeof(float) * d));
    is.read(reinterpret_cast<char*>(norm_std_.data()), static_cast<std::streamsize>(sizeof(float) * d));
    if (!is) throw std::runtime_error(source_name + ": truncated off-policy learner state");
    for (std::size_t k = 0; k < d; ++k)
      if (!std::isfinite(norm_mean_[k]) || !(norm_std_[k] > 0.0f) || !std::isfinite(norm_std_[k]))
        throw std::runtime_error(source_name + ": bad normalizer entry " + std::to_string(k));
  }
  trainer_->load(is);
  replay_.load(is);
  streams_.clear();
  forgiven_ = 0;
  if (!v1 && !v2 && (!io::readPod(is, forgiven_) || forgiven_ < 0))
    throw std::runtime_error(source_name + ": corrupt off-policy learner state (forgiven steps)");
  if (v1) {
    next_episode_ = 0;
    for (long long k = 0; k < replay_.size(); ++k) next_episode_ = std::max(next_episode_, replay_.episodeAt(k) + 1);
  } else {
    long long n = 0;
    if (!io::readPod(is, next_episode_) || !io::readPod(is, n) || next_episode_ < 0 || n < 0 || n > (1 << 24))
      throw std::runtime_error(source_name + ": corrupt off-policy learner streams");
    for (long long k = 0; k < n; ++k) {
      int64_t id = 0;
      long long len = 0;
      StreamTail tail;
      if (!io::readPod(is, id) || !io::readPod(is, tail.episode) || !io::readPod(is, len) || len != spec_.obsDim() ||
          tail.episode < 0 || tail.episode >= next_episode_)
        throw std::runtime_error(source_name + ": corrupt off-policy learner stream " + std::to_string(k));
      tail.last_obs.resize(static_cast<std::size_t>(len));
      is.read(reinterpret_cast<char*>(tail.last_obs.data()), static_cast<std::streamsize>(sizeof(float) * len));
      streams_[id] = std::move(tail);
    }
    if (!is) throw std::runtime_error(source_name + ": truncated off-policy learner state");
  }
  if (fitted_) applyNormalizer();
}

}  // namespace masa::sac
