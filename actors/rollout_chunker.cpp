#include "actors/rollout_chunker.hpp"

#include <algorithm>
#include <cstring>
#include <string_view>

#include "common/core/check.hpp"
#include "common/rollout/rollout_fields.hpp"
#include "common/transport/chunk_layout.hpp"

namespace masa::actor {

RolloutChunker::RolloutChunker(int byte_budget) : budget_(byte_budget) {
  MASA_CHECK(byte_budget > 0, "chunk byte budget must be positive, got " << byte_budget);
}

// Every size below is a difference of chunkEncodedBytes, which walks the wire table: the budget
// arithmetic follows the .lcm file without a formula of its own.
int RolloutChunker::emptyChunkBytes(int act_dim, const std::vector<std::string>& term_names) {
  int64_t name_bytes = 0;
  for (const std::string& s : term_names) name_bytes += static_cast<int64_t>(s.size());
  rollout::ChunkShape shape;
  shape.act_dim = act_dim;
  shape.num_terms = static_cast<int64_t>(term_names.size());
  return static_cast<int>(rollout::chunkEncodedBytes(shape, name_bytes));
}

int RolloutChunker::envBytes(int horizon, int obs_dim, int act_dim) {
  rollout::ChunkShape none{horizon, 0, obs_dim, act_dim}, one{horizon, 1, obs_dim, act_dim};
  return static_cast<int>(rollout::chunkEncodedBytes(one, 0) - rollout::chunkEncodedBytes(none, 0));
}

int RolloutChunker::finalBytes(int obs_dim) {
  rollout::ChunkShape none{0, 0, obs_dim}, one{0, 0, obs_dim};
  one.num_final = 1;
  return static_cast<int>(rollout::chunkEncodedBytes(one, 0) - rollout::chunkEncodedBytes(none, 0));
}

int RolloutChunker::episodeBytes(int num_terms) {
  rollout::ChunkShape none, one;
  none.num_terms = one.num_terms = num_terms;
  one.num_episodes = 1;
  return static_cast<int>(rollout::chunkEncodedBytes(one, 0) - rollout::chunkEncodedBytes(none, 0));
}

int RolloutChunker::maxEnvsPerChunk(int byte_budget, int horizon, int obs_dim, int act_dim,
                                    const std::vector<std::string>& term_names) {
  const int room = byte_budget - emptyChunkBytes(act_dim, term_names);
  return std::max(1, room / envBytes(horizon, obs_dim, act_dim));
}

void RolloutChunker::plan(const rollout::Rollout& r) {
  const int E = r.num_envs;
  env_finals_.assign(E, 0);
  env_episodes_.assign(E, 0);
  for (int32_t idx : r.final_index) ++env_finals_[idx % E];
  for (int32_t e : r.episode_env) ++env_episodes_[e];

  const int empty = emptyChunkBytes(r.act_dim, r.term_names);
  const int per_env = envBytes(r.horizon, r.obs_dim, r.act_dim);
  const int per_final = finalBytes(r.obs_dim), per_episode = episodeBytes(r.numTerms());
  chunk_offset_.clear();
  chunk_envs_.clear();
  int offset = 0, n = 0, bytes = empty;
  for (int e = 0; e < E; ++e) {
    const int add = per_env + env_finals_[e] * per_final + env_episodes_[e] * per_episode;
    if (n > 0 && bytes + add > budget_) {
      chunk_offset_.push_back(offset);
      chunk_envs_.push_back(n);
      offset = e;
      n = 0;
      bytes = empty;
    }
    ++n;
    bytes += add;
  }
  chunk_offset_.push_back(offset);
  chunk_envs_.push_back(n);
}

std::span<const masa::lcmt_rollout_chunk> RolloutChunker::split(const rollout::Rollout& r, const RolloutIdentity& id) {
  MASA_CHECK(r.num_envs > 0 && r.horizon > 0, "rollout not allocated");
  MASA_CHECK(r.final_obs.size() == r.final_index.size() * r.obs_dim, "final_obs size does not match final_index");
  MASA_CHECK(r.episode_term_sums.size() == r.episode_env.size() * r.term_names.size(),
             "episode_term_sums size does not match episodes x terms");
  plan(r);
  const int num_chunks = static_cast<int>(chunk_envs_.size());
  if (static_cast<int>(chunks_.size()) < num_chunks) {
    // New messages are reserved for the largest chunk this shape allows, so later rollouts whose
    // packing shifts still fit without reallocating.
    const int cap = std::min(r.num_envs, maxEnvsPerChunk(budget_, r.horizon, r.obs_dim, r.act_dim, r.term_names));
    // At most one truncation and one episode per step (the chunk layout's lengths at that shape).
    const int64_t steps = int64_t{cap} * r.horizon;
    const rollout::ChunkShape most{r.horizon, cap, r.obs_dim, r.act_dim, steps, steps, r.numTerms()};
    auto length = [&](std::string_view field) { return static_cast<std::size_t>(rollout::chunkLength(field, most)); };
    while (static_cast<int>(chunks_.size()) < num_chunks) {
      masa::lcmt_rollout_chunk& c = chunks_.emplace_back();
      rollout::forEachStepArray(c, r.obs_dim, r.act_dim, [&](auto& a, int width, int extra_rows) {
        a.reserve(static_cast<std::size_t>(r.horizon + extra_rows) * cap * width);
      });
      rollout::forEachFinalArray(c, r.obs_dim, [&](auto& a, int width) { a.reserve(length("num_final") * width); });
      rollout::forEachEpisodeArray(c, r.numTerms(), [&](auto& a, int width) { a.reserve(length("num_episodes") * width); });
    }
  }
  const int empty = emptyChunkBytes(r.act_dim, r.term_names);
  for (int i = 0; i < num_chunks; ++i) {
    masa::lcmt_rollout_chunk& c = chunks_[i];
    fill(c, r, id, i, num_chunks, chunk_offset_[i], chunk_envs_[i]);
    const int expected = empty + chunk_envs_[i] * envBytes(r.horizon, r.obs_dim, r.act_dim) +
                         c.num_final * finalBytes(r.obs_dim) + c.num_episodes * episodeBytes(r.numTerms());
    // Keeps the size arithmetic above honest if the .lcm layout changes.
    MASA_CHECK(c.getEncodedSize() == expected,
               "chunk size formula out of date: " << c.getEncodedSize() << " != " << expected);
    if (expected > budget_) ++oversize_;
  }
  return {chunks_.data(), static_cast<std::size_t>(num_chunks)};
}

void RolloutChunker::fill(masa::lcmt_rollout_chunk& c, const rollout::Rollout& r, const RolloutIdentity& id, int index,
                          int num_chunks, int offset, int n) {
  const int E = r.num_envs, T = r.horizon;
  c.run_id = id.run_id;
  c.actor_id = id.actor_id;
  c.incarnation = id.incarnation;
  c.rollout_seq = id.rollout_seq;
  c.chunk_index = index;
  c.num_chunks = num_chunks;
  c.policy_version = id.policy_version;
  c.horizon = T;
  c.obs_dim = r.obs_dim;
  c.act_dim = r.act_dim;
  c.num_envs = n;
  c.env_offset = offset;

  // Environments [offset, offset + n) of the rollout are the chunk's 0..n-1; its episodes name the
  // actor's environment (env_offset + j), as the wire layout says.
  env_map_.assign(E, -1);
  for (int j = 0; j < n; ++j) env_map_[offset + j] = j;
  const rollout::EnvCopy copy{.horizon = T, .obs_dim = r.obs_dim, .act_dim = r.act_dim, .src_envs = E,
                             .dst_envs = n, .dst_env = env_map_, .dst_episode_base = offset,
                             .src_terms = r.numTerms(), .dst_terms = r.numTerms()};
  rollout::resizeSteps(c, T, n, r.obs_dim, r.act_dim);
  rollout::copyEnvironmentSteps(r, c, copy);
  c.obs_len = static_cast<int32_t>(c.obs.size());
  c.act_len = static_cast<int32_t>(c.actions.size());
  c.step_len = static_cast<int32_t>(c.log_prob.size());
  // One log std per chunk on the wire: an actor's environments all act with the same policy.
  const float* log_std = r.logStdOf(offset);
  for (int e = offset + 1; e < offset + n; ++e)
    MASA_CHECK(std::memcmp(r.logStdOf(e), log_std, r.act_dim * sizeof(float)) == 0,
               "environments " << offset << " and " << e << " of one chunk acted with different log stds");
  c.log_std.assign(log_std, log_std + r.act_dim);
  c.log_std_len = static_cast<int32_t>(c.log_std.size());

  // Truncations stay in ascending order: the global order is (t, e) and the chunk's envs are a
  // contiguous range, so keeping the source's order keeps (t, local e) ascending.
  rollout::clearEvents(c);
  rollout::appendEnvironmentEvents(r, c, copy);
  c.num_final = static_cast<int32_t>(c.final_index.size());
  c.final_obs_len = static_cast<int32_t>(c.final_obs.size());

  c.num_episodes = static_cast<int32_t>(c.episode_env.size());
  c.term_names = r.term_names;  // element-wise assignment: reuses the strings' storage
  c.num_terms = static_cast<int32_t>(c.term_names.size());
  c.term_sums_len = static_cast<int32_t>(c.episode_term_sums.size());
}

}  // namespace masa::actor
