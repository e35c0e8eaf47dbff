// The one table of what a rollout chunk holds (common/transport/chunk_layout.hpp) against the wire
// table (which a hash test ties to lcm-gen), lcm-gen's own encoder, and the learner's validator.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "actors/rollout_chunker.hpp"
#include "common/transport/chunk_layout.hpp"
#include "learner/intake/rollout_assembler.hpp"
#include "masa/lcmt_rollout_chunk.hpp"
#include "test_transport_support.hpp"

namespace masa::rollout {
namespace {

TEST(ChunkLayout, EveryLengthFieldOfTheWireTableHasExactlyOneRule) {
  std::set<std::string> length_fields, rules;
  for (const auto& f : transport::WireLayoutOf<masa::lcmt_rollout_chunk>::fields)
    if (!f.length.empty()) length_fields.insert(std::string(f.length));
  for (const auto& r : kChunkLengthRules) EXPECT_TRUE(rules.insert(std::string(r.field)).second) << r.field;
  EXPECT_EQ(rules, length_fields);
  EXPECT_THROW(chunkLength("no_such_len", ChunkShape{}), std::logic_error);
}

TEST(ChunkLayout, EncodedBytesMatchLcmGensEncoderForEveryChunkOfRandomRollouts) {
  for (const auto& shape : {transport::testing::kHumanoid, transport::testing::kTrifinger}) {
    for (uint64_t seed = 1; seed <= 5; ++seed) {
      Rollout r;
      transport::testing::fillRandomRollout(r, shape, seed, 0.1);
      actor::RolloutChunker chunker(20000);
      int64_t name_bytes = 0;
      for (const auto& n : r.term_names) name_bytes += static_cast<int64_t>(n.size());
      for (const auto& c : chunker.split(r, {1, 0, 0, 0})) {
        const ChunkShape s{c.horizon, c.num_envs, c.obs_dim, c.act_dim, c.num_final, c.num_episodes, c.num_terms};
        EXPECT_EQ(chunkEncodedBytes(s, name_bytes), c.getEncodedSize());
        for (const auto& rule : kChunkLengthRules) EXPECT_GE(rule.length(s), 0) << rule.field;
      }
    }
  }
}

// Each length field one off is refused as a bad length, whatever the field.
TEST(ChunkLayout, TheValidatorRefusesAChunkWhoseLengthFieldDisagreesWithTheTable) {
  const auto shape = transport::testing::kTrifinger;
  Rollout r;
  transport::testing::fillRandomRollout(r, shape, 7, 0.1);
  actor::RolloutChunker chunker;
  const masa::lcmt_rollout_chunk good = chunker.split(r, {1, 0, 0, 0})[0];
  learner::AssemblerConfig cfg;
  cfg.run_id = 1;
  cfg.horizon = shape.horizon;
  cfg.obs_dim = shape.obs_dim;
  cfg.act_dim = shape.act_dim;
  cfg.warn_interval_s = -1;
  {
    learner::RolloutAssembler a(cfg);
    ASSERT_TRUE(a.accept(good));
  }
  for (auto field : {&masa::lcmt_rollout_chunk::obs_len, &masa::lcmt_rollout_chunk::act_len,
                     &masa::lcmt_rollout_chunk::step_len, &masa::lcmt_rollout_chunk::log_std_len,
                     &masa::lcmt_rollout_chunk::final_obs_len, &masa::lcmt_rollout_chunk::term_sums_len}) {
    masa::lcmt_rollout_chunk bad = good;
    bad.*field += 1;
    learner::RolloutAssembler a(cfg);
    EXPECT_EQ(a.accept(bad).reason, learner::DropReason::kBadLength);
  }
}

}  // namespace
}  // namespace masa::rollout
