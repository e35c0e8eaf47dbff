#include "common/transport/rollout_assembler.hpp"

#include <cstring>
#include <iostream>
#include <new>
#include <stdexcept>

#include "common/core/check.hpp"
#include "common/transport/chunk_wire_guard.hpp"

namespace masa::transport {

namespace {

// Exponent all ones = Inf or NaN; a bit test rather than std::isfinite so the loop vectorizes
// and stays correct under -ffast-math.
bool allFinite(const std::vector<float>& v) {
  uint32_t bad = 0;
  for (float f : v) {
    uint32_t b;
    std::memcpy(&b, &f, sizeof b);
    bad |= static_cast<uint32_t>((b & 0x7f800000u) == 0x7f800000u);
  }
  return bad == 0;
}

bool allFlags(const std::vector<int8_t>& v) {
  uint8_t bad = 0;
  for (int8_t x : v) bad |= static_cast<uint8_t>(x != 0 && x != 1);
  return bad == 0;
}

template <typename V>
bool sizeIs(const V& v, int64_t n) {
  return static_cast<int64_t>(v.size()) == n;
}

void clearArrays(masa::lcmt_rollout_chunk& m) {
  // The generated decoder leaves an array untouched when its length is 0, so a reused message
  // would keep the previous chunk's contents there.
  m.obs.clear();
  m.actions.clear();
  m.mean.clear();
  m.log_prob.clear();
  m.reward.clear();
  m.terminated.clear();
  m.truncated.clear();
  m.log_std.clear();
  m.final_index.clear();
  m.final_obs.clear();
  m.episode_env.clear();
  m.episode_return.clear();
  m.episode_length.clear();
  m.episode_success.clear();
  m.term_names.clear();
  m.episode_term_sums.clear();
}

}  // namespace

RolloutAssembler::RolloutAssembler(const AssemblerConfig& config) : cfg_(config) {
  MASA_CHECK(cfg_.horizon > 0 && cfg_.obs_dim > 0 && cfg_.act_dim > 0,
             "assembler needs the learner's horizon, obs_dim and act_dim");
  MASA_CHECK(cfg_.max_policy_lag >= 0, "max_policy_lag must be >= 0");
  MASA_CHECK(cfg_.dedup_window >= 1 && cfg_.max_actors >= 1 && cfg_.max_envs_per_actor >= 1,
             "assembler limits must be positive");
}

DropReason RolloutAssembler::validate(const masa::lcmt_rollout_chunk& m) const {
  if (m.run_id != cfg_.run_id) return DropReason::kWrongRun;
  if (m.horizon != cfg_.horizon || m.obs_dim != cfg_.obs_dim || m.act_dim != cfg_.act_dim) {
    return DropReason::kWrongDims;
  }
  const int64_t T = m.horizon, n = m.num_envs, od = m.obs_dim, ad = m.act_dim;
  if (m.actor_id < 0 || m.actor_id >= cfg_.max_actors || m.rollout_seq < 0 || m.num_chunks < 1 ||
      m.num_chunks > cfg_.max_envs_per_actor || m.chunk_index < 0 || m.chunk_index >= m.num_chunks || n < 1 ||
      m.env_offset < 0 || int64_t{m.env_offset} + n > cfg_.max_envs_per_actor) {
    return DropReason::kOutOfRange;
  }

  // Length fields against the dimensions, and every array against its length field (a message
  // built in-process can disagree; a decoded one cannot).
  const int64_t steps = T * n;
  if (m.obs_len != (T + 1) * n * od || m.act_len != steps * ad || m.step_len != steps || m.log_std_len != ad ||
      m.num_final < 0 || m.num_final > steps || m.final_obs_len != int64_t{m.num_final} * od ||
      m.num_episodes < 0 || m.num_episodes > steps || m.num_terms < 0 || m.num_terms > cfg_.max_terms ||
      m.term_sums_len != int64_t{m.num_episodes} * m.num_terms) {
    return DropReason::kBadLength;
  }
  if (!sizeIs(m.obs, m.obs_len) || !sizeIs(m.actions, m.act_len) || !sizeIs(m.mean, m.act_len) ||
      !sizeIs(m.log_prob, m.step_len) || !sizeIs(m.reward, m.step_len) || !sizeIs(m.terminated, m.step_len) ||
      !sizeIs(m.truncated, m.step_len) || !sizeIs(m.log_std, m.log_std_len) || !sizeIs(m.final_index, m.num_final) ||
      !sizeIs(m.final_obs, m.final_obs_len) || !sizeIs(m.episode_env, m.num_episodes) ||
      !sizeIs(m.episode_return, m.num_episodes) || !sizeIs(m.episode_length, m.num_episodes) ||
      !sizeIs(m.episode_success, m.num_episodes) || !sizeIs(m.term_names, m.num_terms) ||
      !sizeIs(m.episode_term_sums, m.term_sums_len)) {
    return DropReason::kBadLength;
  }

  if (m.policy_version > version_) return DropReason::kFutureVersion;
  if (m.policy_version < version_ - cfg_.max_policy_lag) return DropReason::kTooOld;

  // Flags, truncation indices (exactly the truncated steps, ascending) and episode fields.
  if (!allFlags(m.terminated) || !allFlags(m.truncated)) return DropReason::kOutOfRange;
  int64_t num_truncated = 0;
  for (int8_t x : m.truncated) num_truncated += x;
  if (num_truncated != m.num_final) return DropReason::kOutOfRange;
  for (int i = 0; i < m.num_final; ++i) {
    const int32_t idx = m.final_index[i];
    if (idx < 0 || idx >= steps || (i > 0 && idx <= m.final_index[i - 1]) || m.truncated[idx] != 1) {
      return DropReason::kOutOfRange;
    }
  }
  for (int i = 0; i < m.num_episodes; ++i) {
    const int32_t e = m.episode_env[i];
    const int8_t s = m.episode_success[i];
    if (e < m.env_offset || e >= int64_t{m.env_offset} + n || m.episode_length[i] < 1 || s < -1 || s > 1) {
      return DropReason::kOutOfRange;
    }
  }

  if (!allFinite(m.obs) || !allFinite(m.actions) || !allFinite(m.mean) || !allFinite(m.log_prob) ||
      !allFinite(m.reward) || !allFinite(m.log_std) || !allFinite(m.final_obs) || !allFinite(m.episode_return) ||
      !allFinite(m.episode_term_sums)) {
    return DropReason::kNonFinite;
  }
  return DropReason::kAccepted;
}

DropReason RolloutAssembler::markSeen(const masa::lcmt_rollout_chunk& m) {
  if (static_cast<int>(actors_.size()) <= m.actor_id) actors_.resize(m.actor_id + 1);
  std::vector<SeenRollout>& window = actors_[m.actor_id].rollouts;
  if (window.empty()) window.resize(cfg_.dedup_window);

  SeenRollout* slot = nullptr;
  SeenRollout* oldest = &window[0];
  int64_t newest_seq = -1;
  bool full = true;
  for (SeenRollout& r : window) {
    if (r.seq == m.rollout_seq) slot = &r;
    if (r.seq < 0) full = false;
    if (r.seq < oldest->seq) oldest = &r;
    newest_seq = std::max(newest_seq, r.seq);
  }
  if (slot == nullptr) {
    if (full && m.rollout_seq < oldest->seq) {
      // Far behind everything remembered: an actor that restarted its count (accept and start
      // over); merely behind the window: a replay or a straggler we can no longer check.
      if (m.rollout_seq + 2 * int64_t{cfg_.dedup_window} >= newest_seq) return DropReason::kDuplicate;
      for (SeenRollout& r : window) r.seq = -1;
      oldest = &window[0];
    }
    slot = oldest;
    slot->seq = m.rollout_seq;
    slot->num_chunks = m.num_chunks;
    slot->bits.assign((m.num_chunks + 63) / 64, 0);
  } else if (slot->num_chunks != m.num_chunks) {
    return DropReason::kOutOfRange;  // chunks of one rollout disagree on how many there are
  }
  uint64_t& word = slot->bits[m.chunk_index / 64];
  const uint64_t bit = uint64_t{1} << (m.chunk_index % 64);
  if (word & bit) return DropReason::kDuplicate;
  word |= bit;
  return DropReason::kAccepted;
}

Verdict RolloutAssembler::finish(DropReason reason, const masa::lcmt_rollout_chunk* m) {
  ++stats_.count[static_cast<int>(reason)];
  Verdict v;
  v.reason = reason;
  if (reason == DropReason::kAccepted) {
    v.chunk = ValidatedChunk(m);
    return v;
  }
  const int r = static_cast<int>(reason);
  if (cfg_.warn_interval_s >= 0) {
    const auto now = std::chrono::steady_clock::now();
    if (!warned_[r] || std::chrono::duration<double>(now - last_warn_[r]).count() >= cfg_.warn_interval_s) {
      std::cerr << "masa transport: dropped rollout chunk (" << dropReasonName(reason) << ")";
      if (m != nullptr) {
        std::cerr << " from actor " << m->actor_id << " rollout " << m->rollout_seq << " chunk " << m->chunk_index
                  << " version " << m->policy_version << " (learner at " << version_ << ")";
      }
      if (suppressed_[r] > 0) std::cerr << "; " << suppressed_[r] << " more for this reason not shown";
      std::cerr << "; total " << stats_.count[r] << "\n";
      warned_[r] = true;
      last_warn_[r] = now;
      suppressed_[r] = 0;
    } else {
      ++suppressed_[r];
    }
  }
  return v;
}

Verdict RolloutAssembler::accept(const masa::lcmt_rollout_chunk& msg) {
  DropReason reason = validate(msg);
  if (reason == DropReason::kAccepted) reason = markSeen(msg);  // only valid chunks mark as seen
  return finish(reason, &msg);
}

Verdict RolloutAssembler::acceptEncoded(const void* data, int size) {
  if (!chunkWireLengthsFit(data, size)) return finish(DropReason::kMalformed, nullptr);
  clearArrays(decoded_);
  int used = -1;
  try {
    used = decoded_.decode(data, 0, size);
  } catch (const std::exception&) {  // bad_alloc / length_error: cannot happen after the guard
    used = -1;
  }
  if (used != size) return finish(DropReason::kMalformed, nullptr);
  return accept(decoded_);
}

}  // namespace masa::transport
