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
  return actors_[actor_id].tally;
}

void RolloutAssembler::closeRollouts(ActorWindow& a, int actor_id, int64_t upto) {
  int64_t lost = 0;
  for (int64_t x = std::max(a.closed + 1, a.first); x <= upto; ++x) {
    const SeenRollout* seen = nullptr;
    for (const SeenRollout& r : a.rollouts)
      if (r.seq == x) seen = &r;
    if (seen == nullptr) {
      lost += a.num_chunks;  // wholly lost: as many chunks as the actor's last rollout had
      continue;
    }
    int arrived = 0;
    for (std::size_t i = 0; i < seen->bits.size(); ++i) arrived += std::popcount(seen->bits[i] | seen->arrived[i]);
    lost += seen->num_chunks - arrived;
  }
  a.closed = std::max(a.closed, upto);
  if (lost == 0) return;
  a.tally.lost += lost;
  const int r = static_cast<int>(DropReason::kLost);
  stats_.count[r] += lost;
  if (warnDue(DropReason::kLost)) {
    std::cerr << "masa transport: " << lost << " rollout chunk(s) from actor " << actor_id
              << " never arrived (network loss, or a receive buffer too small: check net.core.rmem_max)";
    if (suppressed_[r] > 0) std::cerr << "; " << suppressed_[r] << " more such reports not shown";
    std::cerr << "; total lost " << stats_.count[r] << "\n";
    suppressed_[r] = 0;
  }
}

void RolloutAssembler::startNumbering(ActorWindow& a, int actor_id, int64_t incarnation, int64_t seq) {
  const bool restart = a.first >= 0;
  if (restart) closeRollouts(a, actor_id, a.newest);  // the old numbering's last rollouts are final now
  if (cfg_.warn_interval_s >= 0) {
    if (restart) {
      std::cerr << "masa transport: actor " << actor_id << " restarted (incarnation " << incarnation << " after "
                << a.incarnation << ", at its rollout " << seq << "): a new numbering, not replays\n";
    } else {
      std::cerr << "masa transport: actor " << actor_id << " joined\n";
    }
  }
  for (SeenRollout& r : a.rollouts) r.seq = -1;
  a.incarnation = incarnation;
  a.first = a.newest = seq;
  a.closed = seq - 1;
  ++a.tally.numberings;
}

RolloutAssembler::ActorWindow& RolloutAssembler::windowOf(int actor_id) {
  if (static_cast<int>(actors_.size()) <= actor_id) actors_.resize(actor_id + 1);
  ActorWindow& a = actors_[actor_id];
  // Twice the window: rollouts up to dedup_window behind the newest, and out-of-date arrivals up
  // to dedup_window ahead of it.
  if (a.rollouts.empty()) a.rollouts.resize(2 * cfg_.dedup_window);
  return a;
}

RolloutAssembler::SeenRollout* RolloutAssembler::findSlot(ActorWindow& a, int64_t seq) {
  for (SeenRollout& r : a.rollouts)
    if (r.seq == seq) return &r;
  return nullptr;
}

namespace {
void resetSlot(auto& slot, int64_t seq, int32_t num_chunks) {
  slot.seq = seq;
  slot.num_chunks = num_chunks;
  slot.bits.assign((num_chunks + 63) / 64, 0);
  slot.arrived.assign(slot.bits.size(), 0);
}
bool anyBit(const std::vector<uint64_t>& bits) {
  for (uint64_t b : bits)
    if (b != 0) return true;
  return false;
}
}  // namespace

RolloutAssembler::SeenRollout& RolloutAssembler::claimSlot(ActorWindow& a, int64_t seq, int32_t num_chunks) {
  // The slots hold at most dedup_window rollouts behind the newest and dedup_window ahead of it, so
  // the oldest slot is unused or outside the window (its losses already counted).
  SeenRollout* oldest = &a.rollouts[0];
  for (SeenRollout& r : a.rollouts)
    if (r.seq < oldest->seq) oldest = &r;
  resetSlot(*oldest, seq, num_chunks);
  return *oldest;
}

DropReason RolloutAssembler::markAccepted(const masa::lcmt_rollout_chunk& m) {
  ActorWindow& a = windowOf(m.actor_id);
  const int64_t s = m.rollout_seq, w = cfg_.dedup_window;
  if (a.first < 0) startNumbering(a, m.actor_id, m.incarnation, s);  // first sight
  if (m.incarnation != a.incarnation) return acceptFarChunk(a, m);

  SeenRollout* slot = findSlot(a, s);
  if (slot == nullptr) {
    if (s > a.newest + w) return acceptFarChunk(a, m);
    if (s <= a.newest - w) return DropReason::kDuplicate;  // behind the window: a replay or a straggler we can no longer check
    if (s > a.newest) {
      a.candidate.seq = -1;  // the numbering moved on: a far rollout seen before it was not a restart
      closeRollouts(a, m.actor_id, s - cfg_.loss_horizon);
      a.newest = s;
    }
    slot = &claimSlot(a, s, m.num_chunks);
  } else if (slot->num_chunks != m.num_chunks) {
    // Chunks of one rollout disagree on how many there are. Only arrivals of out-of-date chunks
    // (perhaps hostile) made the slot so far: the first accepted chunk decides.
    if (anyBit(slot->bits)) return DropReason::kOutOfRange;
    resetSlot(*slot, s, m.num_chunks);
  }
  const std::size_t w64 = m.chunk_index / 64;
  const uint64_t bit = uint64_t{1} << (m.chunk_index % 64);
  if (slot->bits[w64] & bit) return DropReason::kDuplicate;
  const bool first_arrival = !(slot->arrived[w64] & bit);
  slot->bits[w64] |= bit;
  a.num_chunks = m.num_chunks;
  ++a.tally.accepted;
  if (first_arrival && s <= a.closed && a.tally.lost > 0) {
    // Arrived after its rollout's losses were counted: it was not lost after all.
    --a.tally.lost;
    --stats_.count[static_cast<int>(DropReason::kLost)];
  }
  return DropReason::kAccepted;
}

DropReason RolloutAssembler::acceptFarChunk(ActorWindow& a, const masa::lcmt_rollout_chunk& m) {
  SeenRollout& c = a.candidate;
  const int64_t s = m.rollout_seq, w = cfg_.dedup_window;
  const bool same_candidate = c.seq >= 0 && a.candidate_incarnation == m.incarnation;
  if (same_candidate && s > c.seq && s <= c.seq + w) {
    // The far rollout's successor, with no progress of the current numbering in between: a
    // restarted actor (another incarnation), or an outage that lost the rollouts in the gap.
    SeenRollout far = std::move(c);
    c.seq = -1;
    if (m.incarnation != a.incarnation) {
      startNumbering(a, m.actor_id, m.incarnation, far.seq);
    } else {
      closeRollouts(a, m.actor_id, far.seq - cfg_.loss_horizon);
      a.newest = far.seq;
    }
    a.num_chunks = far.num_chunks;
    claimSlot(a, far.seq, far.num_chunks) = std::move(far);
    return markAccepted(m);  // within the window now
  }
  if (!same_candidate || c.seq != s || c.num_chunks != m.num_chunks) {  // replaces an unconfirmed one
    resetSlot(c, s, m.num_chunks);
    a.candidate_incarnation = m.incarnation;
  }
  const std::size_t w64 = m.chunk_index / 64;
  const uint64_t bit = uint64_t{1} << (m.chunk_index % 64);
  if (c.bits[w64] & bit) return DropReason::kDuplicate;
  c.bits[w64] |= bit;
  ++a.tally.accepted;
  return DropReason::kAccepted;
}

void RolloutAssembler::markArrived(const masa::lcmt_rollout_chunk& m) {
  if (m.actor_id >= static_cast<int>(actors_.size())) return;  // an actor never accepted: nothing to follow
  ActorWindow& a = actors_[m.actor_id];
  const int64_t s = m.rollout_seq, w = cfg_.dedup_window;
  if (a.first < 0 || m.incarnation != a.incarnation || s <= a.newest - w || s > a.newest + w) return;
  SeenRollout* slot = findSlot(a, s);
  if (slot == nullptr) {
    slot = &claimSlot(a, s, m.num_chunks);
  } else if (slot->num_chunks != m.num_chunks) {
    return;
  }
  const std::size_t w64 = m.chunk_index / 64;
  const uint64_t bit = uint64_t{1} << (m.chunk_index % 64);
  if ((slot->bits[w64] | slot->arrived[w64]) & bit) return;
  slot->arrived[w64] |= bit;
  if (s <= a.closed && a.tally.lost > 0) {
    --a.tally.lost;
    --stats_.count[static_cast<int>(DropReason::kLost)];
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
  if (reason == DropReason::kAccepted) {
    reason = markAccepted(msg);
  } else if (reason == DropReason::kTooOld || reason == DropReason::kFutureVersion) {
    // Well-formed (the version is checked after the sizes and ranges) and merely out of date: it
    // arrived, so it must not be counted lost. Hostile chunks never mark anything as seen.
    markArrived(msg);
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
