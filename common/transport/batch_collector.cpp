#include "common/transport/batch_collector.hpp"

#include <algorithm>
#include <cstring>

#include "common/core/check.hpp"

namespace masa::transport {

BatchCollector::BatchCollector(const CollectorConfig& config) : cfg_(config) {
  MASA_CHECK(cfg_.num_envs > 0 && cfg_.horizon > 0 && cfg_.obs_dim > 0 && cfg_.act_dim > 0,
             "collector needs num_envs, horizon, obs_dim and act_dim");
  MASA_CHECK(cfg_.max_policy_lag >= 0, "max_policy_lag must be >= 0");
  capacity_ = cfg_.capacity_envs > 0 ? cfg_.capacity_envs : 2 * cfg_.num_envs;
  MASA_CHECK(capacity_ >= cfg_.num_envs, "capacity_envs " << capacity_ << " below num_envs " << cfg_.num_envs);
  const std::size_t C = capacity_, T = cfg_.horizon, od = cfg_.obs_dim, ad = cfg_.act_dim;
  obs_.assign(C * (T + 1) * od, 0.0f);
  actions_.assign(C * T * ad, 0.0f);
  mean_.assign(C * T * ad, 0.0f);
  log_prob_.assign(C * T, 0.0f);
  reward_.assign(C * T, 0.0f);
  terminated_.assign(C * T, 0);
  truncated_.assign(C * T, 0);
  log_std_.assign(C * ad, 0.0f);
  in_use_.assign(C, 0);
  slot_version_.assign(C, 0);
  slot_arrival_.assign(C, 0);
  slot_actor_.assign(C, 0);
  slot_env_.assign(C, 0);
  finals_.resize(C);
  num_finals_.assign(C, 0);
  episodes_.resize(C);
  num_episodes_.assign(C, 0);
  free_.reserve(C);
  for (int s = capacity_ - 1; s >= 0; --s) free_.push_back(s);
  order_.reserve(C);
}

void BatchCollector::release(int s) {
  in_use_[s] = 0;
  num_finals_[s] = 0;
  num_episodes_[s] = 0;
  free_.push_back(s);
  --used_;
}

void BatchCollector::setLearnerVersion(int64_t version) {
  version_ = version;
  for (int s = 0; s < capacity_; ++s) {
    if (in_use_[s] && slot_version_[s] < version_ - cfg_.max_policy_lag) {
      release(s);
      ++stats_.envs_stale;
    }
  }
}

int BatchCollector::freeSlotFor(int64_t version) {
  if (!free_.empty()) {
    const int s = free_.back();
    free_.pop_back();
    return s;
  }
  // Full: make room by evicting the stalest environment, if it is older than the newcomer.
  int victim = -1;
  for (int s = 0; s < capacity_; ++s) {
    if (slot_version_[s] < version && (victim < 0 || slot_version_[s] < slot_version_[victim] ||
                                       (slot_version_[s] == slot_version_[victim] &&
                                        slot_arrival_[s] < slot_arrival_[victim]))) {
      victim = s;
    }
  }
  if (victim < 0) return -1;
  release(victim);
  ++stats_.envs_overflow;
  free_.pop_back();
  return victim;
}

void BatchCollector::add(const ValidatedChunk& chunk) {
  const masa::lcmt_rollout_chunk& m = chunk.msg();
  MASA_CHECK(m.horizon == cfg_.horizon && m.obs_dim == cfg_.obs_dim && m.act_dim == cfg_.act_dim,
             "chunk dimensions differ from the collector's (assembler and collector configured differently)");
  const int n = m.num_envs, T = cfg_.horizon, od = cfg_.obs_dim, ad = cfg_.act_dim;
  if (m.policy_version < version_ - cfg_.max_policy_lag) {
    stats_.envs_stale += n;
    return;
  }
  const int K = static_cast<int>(cfg_.term_names.size());
  const bool terms_match = m.num_terms == K;
  chunk_slots_.assign(n, -1);
  for (int j = 0; j < n; ++j) {
    const int s = freeSlotFor(m.policy_version);
    chunk_slots_[j] = s;
    if (s < 0) {
      ++stats_.envs_overflow;
      continue;
    }
    in_use_[s] = 1;
    ++used_;
    ++stats_.envs_added;
    slot_version_[s] = m.policy_version;
    slot_arrival_[s] = arrivals_++;
    slot_actor_[s] = m.actor_id;
    slot_env_[s] = m.env_offset + j;
    float* obs = obs_.data() + static_cast<std::size_t>(s) * (T + 1) * od;
    for (int t = 0; t <= T; ++t) std::memcpy(obs + t * od, &m.obs[(static_cast<std::size_t>(t) * n + j) * od], od * sizeof(float));
    float* act = actions_.data() + static_cast<std::size_t>(s) * T * ad;
    float* mu = mean_.data() + static_cast<std::size_t>(s) * T * ad;
    for (int t = 0; t < T; ++t) {
      const std::size_t src = (static_cast<std::size_t>(t) * n + j) * ad;
      std::memcpy(act + t * ad, &m.actions[src], ad * sizeof(float));
      std::memcpy(mu + t * ad, &m.mean[src], ad * sizeof(float));
    }
    const std::size_t row = static_cast<std::size_t>(s) * T;
    for (int t = 0; t < T; ++t) {
      const std::size_t src = static_cast<std::size_t>(t) * n + j;
      log_prob_[row + t] = m.log_prob[src];
      reward_[row + t] = m.reward[src];
      terminated_[row + t] = m.terminated[src];
      truncated_[row + t] = m.truncated[src];
    }
    std::memcpy(&log_std_[static_cast<std::size_t>(s) * ad], m.log_std.data(), ad * sizeof(float));
  }
  // Truncations and episodes follow their environment into its slot (if it got one).
  for (int i = 0; i < m.num_final; ++i) {
    const int t = m.final_index[i] / n, j = m.final_index[i] % n;
    const int s = chunk_slots_[j];
    if (s < 0) continue;
    if (static_cast<int>(finals_[s].size()) <= num_finals_[s]) finals_[s].emplace_back();
    Final& f = finals_[s][num_finals_[s]++];
    f.t = t;
    f.obs.assign(&m.final_obs[static_cast<std::size_t>(i) * od], &m.final_obs[static_cast<std::size_t>(i) * od] + od);
  }
  for (int i = 0; i < m.num_episodes; ++i) {
    const int s = chunk_slots_[m.episode_env[i] - m.env_offset];
    if (s < 0) continue;
    if (static_cast<int>(episodes_[s].size()) <= num_episodes_[s]) episodes_[s].emplace_back();
    Episode& ep = episodes_[s][num_episodes_[s]++];
    ep.ret = m.episode_return[i];
    ep.length = m.episode_length[i];
    ep.success = m.episode_success[i];
    ep.term_sums.assign(K, 0.0f);  // a chunk with other reward terms keeps its returns, not its terms
    if (terms_match) std::copy_n(&m.episode_term_sums[static_cast<std::size_t>(i) * K], K, ep.term_sums.begin());
  }
}

bool BatchCollector::take(RolloutBatch& out) {
  if (!ready()) return false;
  const int B = cfg_.num_envs, T = cfg_.horizon, od = cfg_.obs_dim, ad = cfg_.act_dim;
  order_.clear();
  for (int s = 0; s < capacity_; ++s) {
    if (in_use_[s]) order_.push_back(s);
  }
  std::sort(order_.begin(), order_.end(), [&](int a, int b) {
    return slot_version_[a] != slot_version_[b] ? slot_version_[a] < slot_version_[b]
                                                : slot_arrival_[a] < slot_arrival_[b];
  });
  order_.resize(B);

  ActorRollout& d = out.data;
  d.allocate(B, T, od, ad, cfg_.term_names);
  d.clearEvents();
  out.env_log_std.resize(static_cast<std::size_t>(B) * ad);
  out.env_version.resize(B);
  out.env_actor.resize(B);
  out.env_index.resize(B);
  batch_finals_.clear();
  for (int b = 0; b < B; ++b) {
    const int s = order_[b];
    const float* obs = obs_.data() + static_cast<std::size_t>(s) * (T + 1) * od;
    for (int t = 0; t <= T; ++t) std::memcpy(d.obsAt(t, b), obs + t * od, od * sizeof(float));
    const float* act = actions_.data() + static_cast<std::size_t>(s) * T * ad;
    const float* mu = mean_.data() + static_cast<std::size_t>(s) * T * ad;
    const std::size_t row = static_cast<std::size_t>(s) * T;
    for (int t = 0; t < T; ++t) {
      std::memcpy(d.actionAt(t, b), act + t * ad, ad * sizeof(float));
      std::memcpy(d.meanAt(t, b), mu + t * ad, ad * sizeof(float));
      d.log_prob[d.step(t, b)] = log_prob_[row + t];
      d.reward[d.step(t, b)] = reward_[row + t];
      d.terminated[d.step(t, b)] = terminated_[row + t];
      d.truncated[d.step(t, b)] = truncated_[row + t];
    }
    std::memcpy(&out.env_log_std[static_cast<std::size_t>(b) * ad], &log_std_[static_cast<std::size_t>(s) * ad],
                ad * sizeof(float));
    out.env_version[b] = slot_version_[s];
    out.env_actor[b] = slot_actor_[s];
    out.env_index[b] = slot_env_[s];
    for (int i = 0; i < num_finals_[s]; ++i) {
      batch_finals_.emplace_back(static_cast<int32_t>(d.step(finals_[s][i].t, b)), finals_[s][i].obs.data());
    }
    for (int i = 0; i < num_episodes_[s]; ++i) {
      const Episode& ep = episodes_[s][i];
      d.addEpisode(b, ep.ret, ep.length, ep.success, ep.term_sums.data());
    }
  }
  std::copy_n(out.env_log_std.begin(), ad, d.log_std.begin());  // environment 0's; see env_log_std
  std::sort(batch_finals_.begin(), batch_finals_.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [idx, obs] : batch_finals_) d.addFinal(idx / B, idx % B, obs);
  for (int b = 0; b < B; ++b) release(order_[b]);
  ++stats_.batches;
  return true;
}

}  // namespace masa::transport
