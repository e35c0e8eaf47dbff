#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <vector>

#include "learner/intake/batch_collector.hpp"
#include "learner/intake/rollout_assembler.hpp"
#include "actors/rollout_chunker.hpp"
#include "common/transport/wire_guard.hpp"
#include "test_transport_support.hpp"

namespace masa::transport {
namespace {

// The actors' chunking and the learner's intake, tested against each other and the wire.
using namespace masa::actor;
using namespace masa::learner;

using testing::encode;
using testing::fillRandomRollout;
using testing::kHumanoid;
using testing::kTrifinger;
using testing::RolloutShape;

template <typename T>
bool bitwiseSame(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

// Episodes of `r` as tuples ordered by environment (stable), the order a batch keeps them in.
std::vector<std::vector<float>> episodesByEnv(const rollout::Rollout& r) {
  std::vector<int> idx(r.numEpisodes());
  std::iota(idx.begin(), idx.end(), 0);
  std::stable_sort(idx.begin(), idx.end(), [&](int a, int b) { return r.episode_env[a] < r.episode_env[b]; });
  std::vector<std::vector<float>> out;
  for (int i : idx) {
    std::vector<float> row = {static_cast<float>(r.episode_env[i]), r.episode_return[i],
                              static_cast<float>(r.episode_length[i]), static_cast<float>(r.episode_success[i])};
    for (int k = 0; k < r.numTerms(); ++k) row.push_back(r.episode_term_sums[i * r.numTerms() + k]);
    out.push_back(row);
  }
  return out;
}

// Chunker -> bytes -> assembler -> collector, everything that arrives, in env order.
struct Pipeline {
  explicit Pipeline(const RolloutShape& s, int batch_envs)
      : assembler(AssemblerConfig{.run_id = 5, .horizon = s.horizon, .obs_dim = s.obs_dim, .act_dim = s.act_dim, .term_names = {}}),
        collector(CollectorConfig{.num_envs = batch_envs,
                                  .horizon = s.horizon,
                                  .obs_dim = s.obs_dim,
                                  .act_dim = s.act_dim,
                                  .term_names = {"forward_velocity", "alive"}}) {}
  void deliver(const masa::lcmt_rollout_chunk& c) {
    const std::vector<uint8_t> bytes = encode(c);
    const Verdict v = assembler.acceptEncoded(bytes.data(), static_cast<int>(bytes.size()));
    ASSERT_EQ(v.reason, DropReason::kAccepted) << dropReasonName(v.reason);
    collector.add(*v.chunk);
  }
  RolloutAssembler assembler;
  BatchCollector collector;
};

void expectSplitReassemblesExactly(const RolloutShape& shape, int budget, uint64_t seed) {
  SCOPED_TRACE(::testing::Message() << "budget " << budget << " obs " << shape.obs_dim << " seed " << seed);
  rollout::Rollout r;
  fillRandomRollout(r, shape, seed, 0.08);
  RolloutChunker chunker(budget);
  const auto chunks = chunker.split(r, RolloutIdentity{.run_id = 5, .actor_id = 1, .rollout_seq = 0});
  ASSERT_GE(chunks.size(), 1u);

  // Every chunk within the budget (unless a lone environment is bigger than it), and the split is
  // maximal: each chunk could not have taken the next chunk's first environment, which for an
  // ordered split means no split has fewer chunks.
  const int per_env = RolloutChunker::envBytes(shape.horizon, shape.obs_dim, shape.act_dim);
  int envs = 0;
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    const auto& c = chunks[i];
    EXPECT_EQ(c.env_offset, envs);
    EXPECT_EQ(c.chunk_index, static_cast<int>(i));
    EXPECT_EQ(c.num_chunks, static_cast<int>(chunks.size()));
    envs += c.num_envs;
    if (c.num_envs > 1) {
      EXPECT_LE(c.getEncodedSize(), budget);
    }
    if (i + 1 < chunks.size()) {
      // Bytes the next chunk's first environment would have added: its steps, truncations, episodes.
      const int next = chunks[i + 1].env_offset;
      int next_bytes = per_env;
      for (int32_t idx : r.final_index) next_bytes += idx % shape.num_envs == next ? RolloutChunker::finalBytes(shape.obs_dim) : 0;
      for (int32_t e : r.episode_env) next_bytes += e == next ? RolloutChunker::episodeBytes(r.numTerms()) : 0;
      EXPECT_GT(c.getEncodedSize() + next_bytes, budget) << "chunk " << i << " not full";
    }
  }
  EXPECT_EQ(envs, shape.num_envs);

  Pipeline p(shape, shape.num_envs);
  for (const auto& c : chunks) p.deliver(c);
  testing::TakenBatch batch(p.collector.config());
  ASSERT_TRUE(take(p.collector, batch));
  const rollout::Rollout& b = batch.data();
  EXPECT_TRUE(bitwiseSame(b.obs, r.obs));
  EXPECT_TRUE(bitwiseSame(b.actions, r.actions));
  EXPECT_TRUE(bitwiseSame(b.mean, r.mean));
  EXPECT_TRUE(bitwiseSame(b.log_prob, r.log_prob));
  EXPECT_TRUE(bitwiseSame(b.reward, r.reward));
  EXPECT_TRUE(bitwiseSame(b.terminated, r.terminated));
  EXPECT_TRUE(bitwiseSame(b.truncated, r.truncated));
  EXPECT_TRUE(bitwiseSame(b.env_log_std, r.env_log_std));
  EXPECT_TRUE(bitwiseSame(b.final_index, r.final_index));
  EXPECT_TRUE(bitwiseSame(b.final_obs, r.final_obs));
  EXPECT_EQ(episodesByEnv(b), episodesByEnv(r));
  for (int e = 0; e < shape.num_envs; ++e) {
    EXPECT_EQ(batch.origin.env_index[e], e);
    EXPECT_EQ(batch.origin.env_actor[e], 1);
  }
}

TEST(RolloutChunker, SplitUnderSeveralBudgetsReassemblesBitwise) {
  for (const RolloutShape& shape : {kHumanoid, kTrifinger}) {
    for (int budget : {kDefaultChunkBytes, 40000, 20000, 9000, 2000}) {
      for (uint64_t seed : {1u, 2u}) expectSplitReassemblesExactly(shape, budget, seed);
    }
  }
}

TEST(RolloutChunker, ChunkCountIsCeilOfEnvsOverCapacityWithoutEvents) {
  // Humanoid (obs 74, act 21, T 32) and TriFinger (41, 9, 16) at the default budget.
  struct Case {
    RolloutShape shape;
    int per_chunk;
  };
  for (const Case& c : {Case{{64, 32, 74, 21}, 3}, Case{{64, 16, 41, 9}, 14}}) {
    rollout::Rollout r;
    fillRandomRollout(r, c.shape, 3, 0.0);
    r.term_names.clear();
    const int cap = RolloutChunker::maxEnvsPerChunk(kDefaultChunkBytes, c.shape.horizon, c.shape.obs_dim,
                                                    c.shape.act_dim);
    EXPECT_EQ(cap, c.per_chunk);
    RolloutChunker chunker;
    const auto chunks = chunker.split(r, {});
    EXPECT_EQ(static_cast<int>(chunks.size()), (c.shape.num_envs + cap - 1) / cap);
    for (const auto& m : chunks) EXPECT_LE(m.getEncodedSize(), kDefaultChunkBytes);
  }
}

TEST(RolloutChunker, ReusesItsMessagesWithoutReallocating) {
  rollout::Rollout r;
  fillRandomRollout(r, kTrifinger, 1, 0.05);
  RolloutChunker chunker;
  const auto first = chunker.split(r, {});
  std::vector<const float*> obs_data;
  for (const auto& c : first) obs_data.push_back(c.obs.data());
  for (uint64_t seed = 2; seed < 6; ++seed) {
    fillRandomRollout(r, kTrifinger, seed, 0.05);
    const auto again = chunker.split(r, {});
    ASSERT_EQ(again.size(), first.size());
    EXPECT_EQ(again.data(), first.data());
    for (std::size_t i = 0; i < again.size(); ++i) EXPECT_EQ(again[i].obs.data(), obs_data[i]);
  }
}

TEST(RolloutChunker, EnvironmentLargerThanTheBudgetGoesAloneAndIsCounted) {
  rollout::Rollout r;
  fillRandomRollout(r, kHumanoid, 1, 0.0);
  RolloutChunker chunker(10000);  // one humanoid environment is about 15.5 KB
  const auto chunks = chunker.split(r, {});
  EXPECT_EQ(static_cast<int>(chunks.size()), kHumanoid.num_envs);
  EXPECT_EQ(chunker.oversizeChunks(), kHumanoid.num_envs);
}

bool chunkWireLengthsFit(const void* data, int size) {
  return checkWire<masa::lcmt_rollout_chunk>(data, size) == WireVerdict::kOk;
}

TEST(ChunkWireGuard, AcceptsEncodedChunksAndRejectsEveryTruncationOrLengthPastTheEnd) {
  rollout::Rollout r;
  fillRandomRollout(r, kTrifinger, 4, 0.1);
  RolloutChunker chunker(20000);
  const auto chunks = chunker.split(r, {});
  std::vector<uint8_t> bytes = encode(chunks[0]);
  ASSERT_GT(chunks[0].num_final + chunks[0].num_episodes, 0);
  EXPECT_TRUE(chunkWireLengthsFit(bytes.data(), static_cast<int>(bytes.size())));
  for (int cut : {0, 7, 8, 63, 100, static_cast<int>(bytes.size()) - 1}) {
    EXPECT_FALSE(chunkWireLengthsFit(bytes.data(), cut)) << "cut at " << cut;
  }
  std::vector<uint8_t> longer = bytes;
  longer.push_back(0);
  EXPECT_FALSE(chunkWireLengthsFit(longer.data(), static_cast<int>(longer.size())));
  // obs_len sits right after the hash and the 64-byte header: claim 2^31 - 1 floats.
  std::vector<uint8_t> huge = bytes;
  ASSERT_EQ((bytes[72] << 24) | (bytes[73] << 16) | (bytes[74] << 8) | bytes[75], chunks[0].obs_len);
  huge[72] = 0x7f;
  huge[73] = huge[74] = huge[75] = 0xff;
  EXPECT_FALSE(chunkWireLengthsFit(huge.data(), static_cast<int>(huge.size())));
  std::vector<uint8_t> other_hash = bytes;
  other_hash[0] ^= 1;
  EXPECT_FALSE(chunkWireLengthsFit(other_hash.data(), static_cast<int>(other_hash.size())));
}

}  // namespace
}  // namespace masa::transport
