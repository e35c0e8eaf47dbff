#include "learner/intake/rollout_assembler.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <iostream>
#include <new>
#include <stdexcept>
#include <string_view>
#include <type_traits>
#include <utility>

#include "common/core/check.hpp"
#include "common/rollout/rollout_fields.hpp"
#include "common/transport/chunk_layout.hpp"

namespace masa::learner {

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

template <typename V>
bool allFiniteIfFloat(const V& v) {
  if constexpr (std::is_same_v<V, std::vector<float>>) return allFinite(v);
  return true;
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
  rollout::forEachStepArray(m, 1, 1, [](auto& a, int, int) { a.clear(); });
  rollout::clearEvents(m);
  m.log_std.clear();
  m.term_names.clear();
}

}  // namespace

RolloutAssembler::RolloutAssembler(const AssemblerConfig& config) : cfg_(config) {
  MASA_CHECK(cfg_.horizon > 0 && cfg_.obs_dim > 0 && cfg_.act_dim > 0,
             "assembler needs the learner's horizon, obs_dim and act_dim");
  MASA_CHECK(cfg_.max_policy_lag >= 0, "max_policy_lag must be >= 0");
  MASA_CHECK(cfg_.dedup_window >= 1 && cfg_.max_actors >= 1 && cfg_.max_envs_per_actor >= 1,
             "assembler limits must be positive");
  MASA_CHECK(cfg_.loss_horizon >= 1 && cfg_.loss_horizon <= cfg_.dedup_window,
             "loss_horizon must be in [1, dedup_window]");
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
  // The counts first (they are part of the shape), then every length field against the one table
  // of what a chunk of this shape holds (common/transport/chunk_layout.hpp).
  const int64_t steps = T * n;
  if (m.num_final < 0 || m.num_final > steps || m.num_episodes < 0 || m.num_episodes > steps || m.num_terms < 0 ||
      m.num_terms > cfg_.max_terms) {
    return DropReason::kBadLength;
  }
  const rollout::ChunkShape shape{T, n, od, ad, m.num_final, m.num_episodes, m.num_terms};
  const std::pair<std::string_view, int64_t> lengths[] = {
      {"obs_len", m.obs_len},         {"act_len", m.act_len},           {"step_len", m.step_len},
      {"log_std_len", m.log_std_len}, {"final_obs_len", m.final_obs_len}, {"term_sums_len", m.term_sums_len}};
  for (const auto& [field, value] : lengths) {
    if (value != rollout::chunkLength(field, shape)) return DropReason::kBadLength;
  }
  // Every array at the size of its field in the rollout's one list (common/rollout/rollout_fields.hpp),
  // which the length fields, checked above, also say.
  bool sizes = sizeIs(m.log_std, m.log_std_len) && sizeIs(m.term_names, m.num_terms);
  rollout::forEachStepArray(m, od, ad, [&](const auto& a, int width, int extra_rows) {
    sizes = sizes && sizeIs(a, (T + extra_rows) * n * width);
  });
  rollout::forEachFinalArray(m, od, [&](const auto& a, int width) { sizes = sizes && sizeIs(a, m.num_final * int64_t{width}); });
  rollout::forEachEpisodeArray(m, m.num_terms, [&](const auto& a, int width) {
    sizes = sizes && sizeIs(a, m.num_episodes * int64_t{width});
  });
  if (!sizes) return DropReason::kBadLength;
  if (!cfg_.term_names.empty() && m.term_names != cfg_.term_names) return DropReason::kWrongTerms;

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

  // Every float the chunk carries is finite.
  bool finite = allFinite(m.log_std);
  rollout::forEachStepArray(m, od, ad, [&](const auto& a, int, int) { finite = finite && allFiniteIfFloat(a); });
  rollout::forEachFinalArray(m, od, [&](const auto& a, int) { finite = finite && allFiniteIfFloat(a); });
  rollout::forEachEpisodeArray(m, m.num_terms, [&](const auto& a, int) { finite = finite && allFiniteIfFloat(a); });
  if (!finite) return DropReason::kNonFinite;
  return DropReason::kAccepted;
}

const ActorTally& RolloutAssembler::actorTally(int actor_id) const {
  static const ActorTally kNone;
  if (actor_id < 0 || actor_id >= static_cast<int>(actors_.size())) return kNone;
  return actors_[actor_id].tally();
}

ActorNumbering& RolloutAssembler::numberingOf(int actor_id) {
  while (static_cast<int>(actors_.size()) <= actor_id) actors_.emplace_back(cfg_.dedup_window, cfg_.loss_horizon);
  return actors_[actor_id];
}

void RolloutAssembler::apply(int actor_id, const masa::lcmt_rollout_chunk& m, const ActorNumbering::Change& change) {
  const int r = static_cast<int>(DropReason::kLost);
  stats_.count[r] += change.lost - change.found;
  if (change.lost > 0 && warnDue(DropReason::kLost)) {
    std::cerr << "masa transport: " << change.lost << " rollout chunk(s) from actor " << actor_id
              << " never arrived (network loss, or a receive buffer too small: check net.core.rmem_max)";
    if (suppressed_[r] > 0) std::cerr << "; " << suppressed_[r] << " more such reports not shown";
    std::cerr << "; total lost " << stats_.count[r] << "\n";
    suppressed_[r] = 0;
  }
  if (cfg_.warn_interval_s < 0) return;
  if (change.numbering == ActorNumbering::Change::Numbering::kRestarted) {
    std::cerr << "masa transport: actor " << actor_id << " restarted (incarnation " << m.incarnation << " after "
              << change.previous_incarnation << ", at its rollout " << actors_[actor_id].firstRollout()
              << "): a new numbering, not replays\n";
  } else if (change.numbering == ActorNumbering::Change::Numbering::kJoined) {
    std::cerr << "masa transport: actor " << actor_id << " joined\n";
  }
}

bool RolloutAssembler::warnDue(DropReason reason) {
  if (cfg_.warn_interval_s < 0) return false;
  const int r = static_cast<int>(reason);
  const auto now = std::chrono::steady_clock::now();
  if (warned_[r] && std::chrono::duration<double>(now - last_warn_[r]).count() < cfg_.warn_interval_s) {
    ++suppressed_[r];
    return false;
  }
  warned_[r] = true;
  last_warn_[r] = now;
  return true;
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
  if (warnDue(reason)) {
    std::cerr << "masa transport: dropped rollout chunk (" << dropReasonName(reason) << ")";
    if (m != nullptr) {
      std::cerr << " from actor " << m->actor_id << " rollout " << m->rollout_seq << " chunk " << m->chunk_index
                << " version " << m->policy_version << " (learner at " << version_ << ")";
    }
    if (suppressed_[r] > 0) std::cerr << "; " << suppressed_[r] << " more for this reason not shown";
    std::cerr << "; total " << stats_.count[r] << "\n";
    suppressed_[r] = 0;
  }
  return v;
}

Verdict RolloutAssembler::accept(const masa::lcmt_rollout_chunk& msg) {
  DropReason reason = validate(msg);
  const ChunkPlace place{msg.incarnation, msg.rollout_seq, msg.num_chunks, msg.chunk_index};
  ActorNumbering::Change change;
  if (reason == DropReason::kAccepted) {
    reason = numberingOf(msg.actor_id).accept(place, change);
    apply(msg.actor_id, msg, change);
  } else if ((reason == DropReason::kTooOld || reason == DropReason::kFutureVersion) &&
             msg.actor_id < static_cast<int>(actors_.size())) {
    // Well-formed (the version is checked after the sizes and ranges) and merely out of date: it
    // arrived, so it must not be counted lost. Hostile chunks never mark anything as seen, and an
    // actor never accepted has nothing to follow.
    actors_[msg.actor_id].arrived(place, change);
    apply(msg.actor_id, msg, change);
  }
  return finish(reason, &msg);
}

Verdict RolloutAssembler::acceptEncoded(const void* data, int size) {
  clearArrays(decoded_);
  const transport::WireVerdict wire = transport::decodeChecked(data, size, decoded_);
  if (wire != transport::WireVerdict::kOk) {
    ++wire_rejects_[static_cast<int>(wire)];
    return finish(DropReason::kMalformed, nullptr);
  }
  return accept(decoded_);
}

}  // namespace masa::learner
