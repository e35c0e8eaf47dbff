#include "learner/intake/batch_collector.hpp"

#include <algorithm>
#include <cstring>

#include "common/core/check.hpp"
#include "common/rollout/rollout_fields.hpp"

namespace masa::learner {

BatchCollector::BatchCollector(const CollectorConfig& config) : cfg_(config) {
  MASA_CHECK(cfg_.num_envs > 0 && cfg_.horizon > 0 && cfg_.obs_dim > 0 && cfg_.act_dim > 0,
             "collector needs num_envs, horizon, obs_dim and act_dim");
  MASA_CHECK(cfg_.max_policy_lag >= 0, "max_policy_lag must be >= 0");
  capacity_ = cfg_.capacity_envs > 0 ? cfg_.capacity_envs : 2 * cfg_.num_envs;
  MASA_CHECK(capacity_ >= cfg_.num_envs, "capacity_envs " << capacity_ << " below num_envs " << cfg_.num_envs);
  pool_.allocate(capacity_, cfg_.horizon, cfg_.obs_dim, cfg_.act_dim, cfg_.term_names);
  const std::size_t C = capacity_;
  in_use_.assign(C, 0);
  slot_version_.assign(C, 0);
  slot_arrival_.assign(C, 0);
  slot_actor_.assign(C, 0);
  slot_env_.assign(C, 0);
  batch_column_.assign(C, -1);
  free_.reserve(C);
  for (int s = capacity_ - 1; s >= 0; --s) free_.push_back(s);
  order_.reserve(C);
}

void BatchCollector::release(int s) {
  in_use_[s] = 0;
  free_.push_back(s);
  --used_;
  events_stale_ = true;
}

void BatchCollector::dropEventsOfFreeSlots() {
  if (!events_stale_) return;
  events_stale_ = false;
  rollout::Rollout& p = pool_;
  const int C = capacity_, od = p.obs_dim, K = p.numTerms();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < p.final_index.size(); ++i) {
    if (!in_use_[p.final_index[i] % C]) continue;
    p.final_index[kept] = p.final_index[i];
    std::memmove(&p.final_obs[kept * od], &p.final_obs[i * od], od * sizeof(float));
    ++kept;
  }
  p.final_index.resize(kept);
  p.final_obs.resize(kept * od);
  kept = 0;
  for (std::size_t i = 0; i < p.episode_env.size(); ++i) {
    if (!in_use_[p.episode_env[i]]) continue;
    p.episode_env[kept] = p.episode_env[i];
    p.episode_return[kept] = p.episode_return[i];
    p.episode_length[kept] = p.episode_length[i];
    p.episode_success[kept] = p.episode_success[i];
    std::memmove(&p.episode_term_sums[kept * K], &p.episode_term_sums[i * K], K * sizeof(float));
    ++kept;
  }
  p.episode_env.resize(kept);
  p.episode_return.resize(kept);
  p.episode_length.resize(kept);
  p.episode_success.resize(kept);
  p.episode_term_sums.resize(kept * K);
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
  dropEventsOfFreeSlots();  // before the slot is reused: its events are the victim's
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
  rollout::Rollout& p = pool_;
  dropEventsOfFreeSlots();  // before free slots are reused: their events are their previous owners'
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
    std::memcpy(p.logStdOf(s), m.log_std.data(), ad * sizeof(float));
  }
  // Same layout on both sides: environment j of the chunk becomes column s of the pool, and its
  // truncations and episodes follow it (if it got a slot).
  const rollout::EnvCopy copy{.horizon = T, .obs_dim = od, .act_dim = ad, .src_envs = n,
                             .dst_envs = capacity_, .dst_env = chunk_slots_, .src_episode_base = m.env_offset,
                             .src_terms = m.num_terms, .dst_terms = pool_.numTerms()};
  rollout::copyEnvironmentSteps(m, p, copy);
  rollout::appendEnvironmentEvents(m, p, copy);
}

bool BatchCollector::take(rollout::RolloutBuffer& out, BatchOrigin* origin) {
  if (!ready()) return false;
  takeEnvs(out, cfg_.num_envs, origin);
  return true;
}

bool BatchCollector::takeShort(rollout::RolloutBuffer& out, int min_envs, BatchOrigin* origin) {
  MASA_CHECK(min_envs > 0, "a short batch needs at least one environment, asked for " << min_envs);
  if (used_ < min_envs) return false;
  const int n = std::min(used_, cfg_.num_envs);
  takeEnvs(out, n, origin);
  if (n < cfg_.num_envs) ++stats_.short_batches;
  return true;
}

void BatchCollector::takeEnvs(rollout::RolloutBuffer& out, int B, BatchOrigin* origin) {
  const int T = cfg_.horizon, od = cfg_.obs_dim, ad = cfg_.act_dim, C = capacity_;
  MASA_CHECK(out.horizon() == T && out.obsDim() == od && out.actDim() == ad,
             "rollout buffer is " << out.horizon() << " steps, obs " << out.obsDim() << ", act " << out.actDim()
                                  << "; the collector's batches are " << T << " steps, obs " << od << ", act " << ad);
  out.setNumEnvs(B);
  dropEventsOfFreeSlots();
  order_.clear();
  for (int s = 0; s < capacity_; ++s) {
    if (in_use_[s]) order_.push_back(s);
  }
  std::sort(order_.begin(), order_.end(), [&](int a, int b) {
    return slot_version_[a] != slot_version_[b] ? slot_version_[a] < slot_version_[b]
                                                : slot_arrival_[a] < slot_arrival_[b];
  });
  order_.resize(B);

  const rollout::Rollout& p = pool_;
  rollout::Rollout& d = out.data();
  d.allocate(B, T, od, ad, cfg_.term_names);
  d.clearEvents();
  if (origin) {
    origin->env_version.resize(B);
    origin->env_actor.resize(B);
    origin->env_index.resize(B);
  }
  for (int b = 0; b < B; ++b) {
    const int s = order_[b];
    batch_column_[s] = b;
    std::memcpy(d.logStdOf(b), p.logStdOf(s), ad * sizeof(float));
    if (origin) {
      origin->env_version[b] = slot_version_[s];
      origin->env_actor[b] = slot_actor_[s];
      origin->env_index[b] = slot_env_[s];
    }
  }
  // The chosen slots become batch columns, their events renumbered; truncations in ascending order.
  const rollout::EnvCopy copy{.horizon = T, .obs_dim = od, .act_dim = ad, .src_envs = C, .dst_envs = B,
                             .dst_env = batch_column_, .src_terms = p.numTerms(), .dst_terms = p.numTerms()};
  rollout::copyEnvironmentSteps(p, d, copy);
  rollout::appendEnvironmentEvents(p, d, copy);
  rollout::sortFinals(d, od, batch_finals_, sorted_final_obs_);
  for (int b = 0; b < B; ++b) {
    batch_column_[order_[b]] = -1;
    release(order_[b]);
  }
  ++stats_.batches;
}

}  // namespace masa::learner
