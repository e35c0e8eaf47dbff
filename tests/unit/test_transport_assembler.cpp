#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <set>
#include <vector>

#include "learner/intake/batch_collector.hpp"
#include "learner/intake/rollout_assembler.hpp"
#include "actors/rollout_chunker.hpp"
#include "test_transport_support.hpp"

namespace masa::transport {
namespace {

// The actors' chunking and the learner's intake, tested against each other and the wire.
using namespace masa::actor;
using namespace masa::learner;

using testing::encode;
using testing::fillRandomRollout;
using testing::kTrifinger;

constexpr int64_t kRun = 77;

AssemblerConfig assemblerConfig(int lag = 0) {
  AssemblerConfig c;
  c.run_id = kRun;
  c.horizon = kTrifinger.horizon;
  c.obs_dim = kTrifinger.obs_dim;
  c.act_dim = kTrifinger.act_dim;
  c.max_policy_lag = lag;
  c.warn_interval_s = -1;  // these tests drop on purpose
  return c;
}

CollectorConfig collectorConfig(int num_envs, int lag = 0) {
  CollectorConfig c;
  c.num_envs = num_envs;
  c.horizon = kTrifinger.horizon;
  c.obs_dim = kTrifinger.obs_dim;
  c.act_dim = kTrifinger.act_dim;
  c.max_policy_lag = lag;
  c.term_names = {"forward_velocity", "alive"};
  return c;
}

// A rollout of 20 TriFinger environments split 4 per chunk (5 chunks), with truncations and
// episodes in every chunk so their validation is exercised.
std::vector<masa::lcmt_rollout_chunk> makeChunks(int64_t version, int64_t seq = 0, int actor = 0, int64_t incarnation = 1) {
  rollout::Rollout r;
  fillRandomRollout(r, kTrifinger, 100 + seq, 0.1);
  RolloutChunker chunker(4 * RolloutChunker::envBytes(kTrifinger.horizon, kTrifinger.obs_dim, kTrifinger.act_dim) + 3000);
  const auto span = chunker.split(r, RolloutIdentity{.run_id = kRun, .actor_id = actor, .rollout_seq = seq,
                                                     .policy_version = version, .incarnation = incarnation});
  return {span.begin(), span.end()};
}

TEST(RolloutAssembler, LostChunksLoseOnlyTheirEnvironmentsAndNothingWaits) {
  const auto chunks = makeChunks(0);
  ASSERT_GE(chunks.size(), 4u);
  RolloutAssembler assembler(assemblerConfig());
  int arrived_envs = 0;
  std::set<int> arrived;
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    if (i == 1 || i == 3) continue;  // lost on the way
    arrived_envs += chunks[i].num_envs;
    for (int e = 0; e < chunks[i].num_envs; ++e) arrived.insert(chunks[i].env_offset + e);
  }
  BatchCollector collector(collectorConfig(arrived_envs));
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    if (i == 1 || i == 3) continue;
    const Verdict v = assembler.accept(chunks[i]);
    ASSERT_TRUE(v) << dropReasonName(v.reason);
    collector.add(*v.chunk);
  }
  ASSERT_TRUE(collector.ready());
  testing::TakenBatch batch(collector.config());
  ASSERT_TRUE(take(collector, batch));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
  const std::set<int> got(batch.origin.env_index.begin(), batch.origin.env_index.end());
  EXPECT_EQ(got, arrived);
  // The surviving environments carry their own data: obs of batch env b equal the chunk's.
  for (int b = 0; b < batch.data().num_envs; ++b) {
    const int e = batch.origin.env_index[b];
    for (const auto& c : chunks) {
      if (e < c.env_offset || e >= c.env_offset + c.num_envs) continue;
      const int j = e - c.env_offset;
      EXPECT_EQ(batch.data().obsAt(0, b)[0], c.obs[j * c.obs_dim]);
      EXPECT_EQ(batch.data().obsAt(c.horizon, b)[3], c.obs[(c.horizon * c.num_envs + j) * c.obs_dim + 3]);
    }
  }
  // The next rollout goes through as if nothing happened.
  for (const auto& c : makeChunks(0, 1)) EXPECT_TRUE(assembler.accept(c));
  EXPECT_EQ(assembler.stats()[DropReason::kAccepted], static_cast<int64_t>(chunks.size() - 2 + makeChunks(0, 1).size()));
}

struct HostileCase {
  const char* name;
  DropReason reason;
  std::function<void(masa::lcmt_rollout_chunk&)> corrupt;
};

std::vector<HostileCase> hostileCases() {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  return {
      {"obs_dim differs from the learner's", DropReason::kWrongDims,
       [](auto& c) { c.obs_dim += 1; }},
      {"horizon differs from the learner's", DropReason::kWrongDims, [](auto& c) { c.horizon -= 1; }},
      {"obs_len disagrees with the dimensions", DropReason::kBadLength,
       [](auto& c) { c.obs.pop_back(); c.obs_len -= 1; }},
      {"obs array shorter than obs_len", DropReason::kBadLength, [](auto& c) { c.obs.pop_back(); }},
      {"mean array longer than act_len", DropReason::kBadLength, [](auto& c) { c.mean.push_back(0); }},
      {"log_std_len not act_dim", DropReason::kBadLength,
       [](auto& c) { c.log_std.push_back(0); c.log_std_len += 1; }},
      {"final_obs_len not num_final * obs_dim", DropReason::kBadLength,
       [](auto& c) { c.final_obs.resize(c.final_obs.size() + 1); c.final_obs_len += 1; }},
      {"term sums not episodes x terms", DropReason::kBadLength,
       [](auto& c) { c.episode_term_sums.push_back(0); c.term_sums_len += 1; }},
      {"negative num_episodes", DropReason::kBadLength, [](auto& c) { c.num_episodes = -1; }},
      {"NaN in obs", DropReason::kNonFinite, [nan](auto& c) { c.obs[c.obs.size() / 2] = nan; }},
      {"Inf in reward", DropReason::kNonFinite, [inf](auto& c) { c.reward.back() = inf; }},
      {"-Inf in log_prob", DropReason::kNonFinite, [inf](auto& c) { c.log_prob[0] = -inf; }},
      {"NaN in final_obs", DropReason::kNonFinite, [nan](auto& c) { c.final_obs.back() = nan; }},
      {"Inf in episode term sums", DropReason::kNonFinite, [inf](auto& c) { c.episode_term_sums[0] = inf; }},
      {"NaN in log_std", DropReason::kNonFinite, [nan](auto& c) { c.log_std[0] = nan; }},
      {"another run", DropReason::kWrongRun, [](auto& c) { c.run_id = kRun + 1; }},
      {"future version", DropReason::kFutureVersion, [](auto& c) { c.policy_version = 6; }},
      {"version older than the lag allows", DropReason::kTooOld, [](auto& c) { c.policy_version = 3; }},
      {"chunk_index == num_chunks", DropReason::kOutOfRange, [](auto& c) { c.chunk_index = c.num_chunks; }},
      {"negative chunk_index", DropReason::kOutOfRange, [](auto& c) { c.chunk_index = -1; }},
      {"negative env_offset", DropReason::kOutOfRange, [](auto& c) { c.env_offset = -4; }},
      {"env range past the actor limit", DropReason::kOutOfRange, [](auto& c) { c.env_offset = (1 << 16) - 1; }},
      {"negative actor id", DropReason::kOutOfRange, [](auto& c) { c.actor_id = -1; }},
      {"final_index past the steps", DropReason::kOutOfRange,
       [](auto& c) { c.final_index.back() = c.step_len; }},
      {"final_index at a step that is not truncated", DropReason::kOutOfRange,
       [](auto& c) {
         for (int i = 0; i < c.step_len; ++i) {
           if (!c.truncated[i]) {
             c.final_index[0] = i;
             break;
           }
         }
       }},
      {"truncated step without final_obs", DropReason::kOutOfRange,
       [](auto& c) {
         for (int i = 0; i < c.step_len; ++i) {
           if (!c.truncated[i]) {
             c.truncated[i] = 1;
             break;
           }
         }
       }},
      {"terminated flag 2", DropReason::kOutOfRange, [](auto& c) { c.terminated[0] = 2; }},
      {"episode of an environment outside the chunk", DropReason::kOutOfRange,
       [](auto& c) { c.episode_env[0] = c.env_offset + c.num_envs; }},
      {"episode success 5", DropReason::kOutOfRange, [](auto& c) { c.episode_success[0] = 5; }},
      {"episode length 0", DropReason::kOutOfRange, [](auto& c) { c.episode_length[0] = 0; }},
  };
}

TEST(RolloutAssembler, EveryHostileChunkIsDroppedUnderItsReasonAndNeverReachesTheCollector) {
  // Learner at version 5 with lag 1: versions 4 and 5 are acceptable.
  const auto chunks = makeChunks(5);
  masa::lcmt_rollout_chunk good = chunks[0];
  ASSERT_GT(good.num_final, 0);
  ASSERT_GT(good.num_episodes, 0);
  RolloutAssembler assembler(assemblerConfig(1));
  assembler.setLearnerVersion(5);
  BatchCollector collector(collectorConfig(good.num_envs, 1));
  collector.setLearnerVersion(5);

  DropStats expected;
  for (const HostileCase& h : hostileCases()) {
    masa::lcmt_rollout_chunk bad = good;
    h.corrupt(bad);
    const Verdict v = assembler.accept(bad);
    EXPECT_EQ(v.reason, h.reason) << h.name << ": got " << dropReasonName(v.reason);
    EXPECT_FALSE(v.chunk.has_value()) << h.name;
    if (v.chunk) collector.add(*v.chunk);
    ++expected.count[static_cast<int>(h.reason)];
  }
  EXPECT_EQ(collector.bufferedEnvs(), 0);
  EXPECT_EQ(collector.stats().envs_added, 0);
  EXPECT_EQ(assembler.stats().count, expected.count);

  // None of them marked the chunk as seen: the genuine one still goes through, once.
  const Verdict ok = assembler.accept(good);
  ASSERT_TRUE(ok) << dropReasonName(ok.reason);
  collector.add(*ok.chunk);
  EXPECT_EQ(collector.bufferedEnvs(), good.num_envs);
  const Verdict again = assembler.accept(good);
  EXPECT_EQ(again.reason, DropReason::kDuplicate);
  EXPECT_EQ(assembler.stats()[DropReason::kDuplicate], 1);
  EXPECT_EQ(assembler.stats().dropped(), static_cast<int64_t>(hostileCases().size()) + 1);
}

TEST(RolloutAssembler, DuplicateChunkOfAnOlderRolloutIsDroppedButOtherActorsAreIndependent) {
  RolloutAssembler assembler(assemblerConfig());
  const auto a0 = makeChunks(0, 0, /*actor=*/0);
  const auto a1 = makeChunks(0, 1, /*actor=*/0);
  const auto b0 = makeChunks(0, 0, /*actor=*/1);
  for (const auto& c : a0) EXPECT_TRUE(assembler.accept(c));
  for (const auto& c : a1) EXPECT_TRUE(assembler.accept(c));
  for (const auto& c : b0) EXPECT_TRUE(assembler.accept(c));  // same seq, other actor
  EXPECT_EQ(assembler.accept(a0[2]).reason, DropReason::kDuplicate);
  EXPECT_EQ(assembler.accept(b0[0]).reason, DropReason::kDuplicate);
  // A chunk of the same rollout claiming another chunk count is inconsistent.
  masa::lcmt_rollout_chunk odd = a1[0];
  odd.chunk_index = 0;
  odd.num_chunks += 1;
  EXPECT_EQ(assembler.accept(odd).reason, DropReason::kOutOfRange);
}

// A restarted actor (same actor id, a new process) is a new incarnation, numbering its rollouts from
// 0 again: its rollouts are used at once, not taken for replays of the dead process's, and it counts
// as a new numbering once its second rollout follows. Restarts rest on the incarnation alone.
TEST(RolloutAssembler, ARestartedActorIsANewIncarnationAndIsAcceptedAtOnce) {
  RolloutAssembler assembler(assemblerConfig());
  int64_t sent = 0;
  for (int64_t k = 0; k < 5; ++k)  // fewer rollouts than the dedup window remembers
    for (const auto& c : makeChunks(0, k, 0, /*incarnation=*/11)) {
      ASSERT_TRUE(assembler.accept(c));
      ++sent;
    }
  // Killed and restarted: every chunk of every rollout of the new process goes through.
  for (int64_t k = 0; k < 5; ++k) {
    for (const auto& c : makeChunks(0, k, 0, /*incarnation=*/22)) {
      const Verdict v = assembler.accept(c);
      EXPECT_TRUE(v) << "rollout " << k << " of the restarted actor: " << dropReasonName(v.reason);
      ++sent;
    }
    if (k == 0) {
      EXPECT_EQ(assembler.actorTally(0).numberings, 1) << "one rollout alone may be a replay or a forgery";
    }
  }
  EXPECT_EQ(assembler.stats()[DropReason::kAccepted], sent);
  EXPECT_EQ(assembler.stats().dropped(), 0) << "nothing dropped, nothing counted lost";
  EXPECT_EQ(assembler.actorTally(0).numberings, 2);
  EXPECT_EQ(assembler.actorTally(0).accepted, sent);
  // Duplicates are still caught within the new numbering.
  EXPECT_EQ(assembler.accept(makeChunks(0, 4, 0, 22)[0]).reason, DropReason::kDuplicate);
  // A jump far ahead within one incarnation is an outage, never a restart.
  for (int64_t k : {5000, 5001})
    for (const auto& c : makeChunks(0, k, 0, 22)) EXPECT_TRUE(assembler.accept(c));
  EXPECT_EQ(assembler.actorTally(0).numberings, 2);
  EXPECT_GT(assembler.stats()[DropReason::kLost], 0) << "the rollouts of the outage";
}

// A replaying or fuzzing host on the LAN: old chunks sent again, and copies of live chunks with
// wild rollout numbers (accepted as data or dropped for their version). None of them may move the
// actor's numbering: no chunk counted lost, no restart reported.
TEST(RolloutAssembler, ReplayedChunksAndWildRolloutNumbersChangeNeitherLostNorRestarts) {
  RolloutAssembler assembler(assemblerConfig(/*lag=*/1));
  const int64_t start = 0;
  const int kRollouts = 40;  // well past twice the dedup window
  std::vector<std::vector<masa::lcmt_rollout_chunk>> sent;
  for (int k = 0; k < kRollouts; ++k) {
    assembler.setLearnerVersion(k);
    sent.push_back(makeChunks(k, start + k));
    for (const auto& c : sent.back()) ASSERT_TRUE(assembler.accept(c));
  }
  ASSERT_EQ(assembler.stats()[DropReason::kLost], 0);
  ASSERT_EQ(assembler.actorTally(0).numberings, 1);

  // Replays of every old chunk, oldest first (too old for the learner now, or duplicates).
  for (const auto& rollout : sent)
    for (const auto& c : rollout) EXPECT_FALSE(assembler.accept(c));
  EXPECT_EQ(assembler.stats()[DropReason::kLost], 0) << "replays";
  EXPECT_EQ(assembler.actorTally(0).numberings, 1) << "replays";

  // Copies of the newest rollout's chunks with wild numbers, at the current version (they pass
  // every check) and at an old one (dropped as too old).
  const int64_t newest = start + kRollouts - 1;
  for (int64_t wild : {newest + 1000, newest + 100'000, newest - 1000, int64_t{0}, int64_t{1} << 50, newest + 40,
                       newest - 40, newest + 5000}) {
    for (int64_t version : {int64_t{kRollouts - 1}, int64_t{0}}) {
      for (masa::lcmt_rollout_chunk c : sent.back()) {
        c.rollout_seq = wild;
        c.policy_version = version;
        assembler.accept(c);
      }
    }
  }
  EXPECT_EQ(assembler.stats()[DropReason::kLost], 0) << "wild rollout numbers";
  EXPECT_EQ(assembler.actorTally(0).numberings, 1) << "wild rollout numbers";
  // ... and with wild incarnations: each is one rollout of a would-be restart, never confirmed.
  for (int64_t wild : {int64_t{2}, int64_t{0}, int64_t{-1}, int64_t{1} << 62, int64_t{12345}}) {
    for (masa::lcmt_rollout_chunk c : sent.back()) {
      c.incarnation = wild;
      c.policy_version = kRollouts - 1;
      assembler.accept(c);
    }
  }
  EXPECT_EQ(assembler.stats()[DropReason::kLost], 0) << "wild incarnations";
  EXPECT_EQ(assembler.actorTally(0).numberings, 1) << "wild incarnations";

  // The real actor goes on: its next rollouts are accepted, nothing is lost.
  for (int k = kRollouts; k < kRollouts + 3; ++k) {
    assembler.setLearnerVersion(k);
    for (const auto& c : makeChunks(k, start + k)) EXPECT_TRUE(assembler.accept(c)) << "rollout " << k;
  }
  EXPECT_EQ(assembler.stats()[DropReason::kLost], 0);
  EXPECT_EQ(assembler.actorTally(0).numberings, 1);
}

TEST(RolloutAssembler, ARestartThatKeptItsIncarnationWouldBeTakenForReplays) {
  // Why every masa_actor process picks a new incarnation: a restarted process's first rollouts,
  // numbered from 0, would collide with the dead one's, within the window, and be dropped as
  // duplicates.
  RolloutAssembler assembler(assemblerConfig());
  for (int64_t k = 0; k < 5; ++k)
    for (const auto& c : makeChunks(0, k)) ASSERT_TRUE(assembler.accept(c));
  EXPECT_EQ(assembler.accept(makeChunks(0, 0)[0]).reason, DropReason::kDuplicate);
}

TEST(RolloutAssembler, ChunksThatNeverArriveAreCountedAsLostOnceTheActorIsTwoRolloutsPast) {
  RolloutAssembler assembler(assemblerConfig());
  ASSERT_EQ(assembler.config().loss_horizon, 2);
  const int64_t base = 5000;
  auto chunksOf = [&](int64_t k) { return makeChunks(0, base + k, /*actor=*/1); };
  auto send = [&](int64_t k, int skip_chunk = -1) {
    const auto chunks = chunksOf(k);
    for (int i = 0; i < static_cast<int>(chunks.size()); ++i) {
      if (i == skip_chunk) continue;
      ASSERT_TRUE(assembler.accept(chunks[i]));
    }
  };
  send(0, /*skip_chunk=*/1);
  send(1);
  EXPECT_EQ(assembler.stats()[DropReason::kLost], 0) << "rollout 0 may still be completed by a late chunk";
  // Rollout 2 never arrives at all.
  send(3);
  EXPECT_EQ(assembler.stats()[DropReason::kLost], 1) << "rollout 0's chunk 1, once rollout 2 could have come";
  send(4);
  // A wholly lost rollout counts as many chunks as the actor's last rollout (3) had.
  const int64_t lost = 1 + static_cast<int64_t>(chunksOf(3).size());
  EXPECT_EQ(assembler.stats()[DropReason::kLost], lost);
  EXPECT_EQ(assembler.actorTally(1).lost, lost);
  EXPECT_EQ(assembler.actorTally(0).lost, 0) << "other actors are untouched";
  EXPECT_EQ(assembler.stats().dropped(), lost) << "lost chunks are part of the drop total";
  // Rollouts 5 to 104 lost on the way (an outage): counted, not taken for a restart.
  send(105);
  send(106);
  send(107);
  EXPECT_EQ(assembler.actorTally(1).numberings, 1);
  // 5..103 were counted when 105 came (estimated with rollout 4's chunk count), 104 when 106 came.
  const int64_t after_outage = lost + 99 * static_cast<int64_t>(chunksOf(4).size()) + chunksOf(105).size();
  EXPECT_EQ(assembler.stats()[DropReason::kLost], after_outage);
  EXPECT_EQ(assembler.accept(chunksOf(4)[0]).reason, DropReason::kDuplicate) << "behind the window";
  EXPECT_EQ(assembler.stats()[DropReason::kLost], after_outage);
  // A chunk of rollout 2 turning up late is still used, and no longer counted lost.
  // (Within the dedup window only; rollout 2 is far behind now, so go back to the state before.)
  RolloutAssembler fresh(assemblerConfig());
  for (int64_t k : {0, 1, 3, 4})
    for (const auto& c : chunksOf(k)) ASSERT_TRUE(fresh.accept(c));
  const int64_t lost_before = fresh.stats()[DropReason::kLost];
  ASSERT_EQ(lost_before, static_cast<int64_t>(chunksOf(4).size()));  // rollout 2, estimated
  ASSERT_TRUE(fresh.accept(chunksOf(2)[0]));
  EXPECT_EQ(fresh.stats()[DropReason::kLost], lost_before - 1);
}

TEST(RolloutAssembler, MalformedBytesAreDroppedWithoutDecodingHostileLengths) {
  RolloutAssembler assembler(assemblerConfig());
  const auto chunks = makeChunks(0);
  std::vector<uint8_t> bytes = encode(chunks[0]);
  // Truncated datagram.
  EXPECT_EQ(assembler.acceptEncoded(bytes.data(), static_cast<int>(bytes.size()) - 10).reason,
            DropReason::kMalformed);
  // obs_len = 2^31 - 1: the generated decoder would allocate 8 GB before noticing. Its offset: the
  // hash, run_id, actor_id, incarnation, rollout_seq, chunk_index, num_chunks, policy_version and
  // the five int32 dimensions before it.
  constexpr int kObsLen = 8 + 8 + 4 + 8 + 8 + 4 + 4 + 8 + 5 * 4;
  ASSERT_EQ(bytes[kObsLen + 3] + 256 * bytes[kObsLen + 2], static_cast<int>(chunks[0].obs_len) % 65536);
  std::vector<uint8_t> huge = bytes;
  huge[kObsLen] = 0x7f;
  huge[kObsLen + 1] = huge[kObsLen + 2] = huge[kObsLen + 3] = 0xff;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(assembler.acceptEncoded(huge.data(), static_cast<int>(huge.size())).reason, DropReason::kMalformed);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(100));
  // Negative length.
  std::vector<uint8_t> negative = bytes;
  negative[kObsLen] = 0x80;
  EXPECT_EQ(assembler.acceptEncoded(negative.data(), static_cast<int>(negative.size())).reason,
            DropReason::kMalformed);
  EXPECT_EQ(assembler.acceptEncoded(nullptr, 0).reason, DropReason::kMalformed);
  EXPECT_EQ(assembler.stats()[DropReason::kMalformed], 4);
  // And why, by the wire guard's reasons.
  EXPECT_EQ(assembler.wireRejects()[static_cast<int>(WireVerdict::kTruncated)], 2);  // the cut and nullptr
  EXPECT_EQ(assembler.wireRejects()[static_cast<int>(WireVerdict::kOverLimit)], 1);
  EXPECT_EQ(assembler.wireRejects()[static_cast<int>(WireVerdict::kNegativeLength)], 1);
  // The intact bytes decode and pass, even after a chunk with empty arrays was decoded into the
  // same reused message (the generated decoder leaves zero-length arrays untouched).
  EXPECT_TRUE(assembler.acceptEncoded(bytes.data(), static_cast<int>(bytes.size())));
  masa::lcmt_rollout_chunk no_events = chunks[1];
  for (int& idx : no_events.final_index) no_events.truncated[idx] = 0;
  no_events.final_index.clear();
  no_events.num_final = 0;
  no_events.final_obs.clear();
  no_events.final_obs_len = 0;
  const std::vector<uint8_t> b2 = encode(no_events);
  const Verdict v = assembler.acceptEncoded(b2.data(), static_cast<int>(b2.size()));
  EXPECT_TRUE(v) << dropReasonName(v.reason);
}

// docs/inputs.md gap 1: term names become metrics.csv's columns and words of the curve's gnuplot
// script; a chunk naming others than the task's (a backquoted command, a comma) is dropped as
// wrong_terms, moves nothing, and the chunk with the task's names still goes through.
TEST(RolloutAssembler, AChunkNamingOtherRewardTermsThanTheTasksIsDropped) {
  const auto chunks = makeChunks(5);
  const masa::lcmt_rollout_chunk& good = chunks[0];
  ASSERT_FALSE(good.term_names.empty());
  AssemblerConfig config = assemblerConfig(1);
  config.term_names = good.term_names;
  RolloutAssembler assembler(config);
  assembler.setLearnerVersion(5);
  for (const std::string& name : std::vector<std::string>{"`touch /tmp/masa_pwned`", "alive,reward", "other"}) {
    masa::lcmt_rollout_chunk bad = good;
    bad.term_names[0] = name;
    const Verdict v = assembler.accept(bad);
    EXPECT_EQ(v.reason, DropReason::kWrongTerms) << name << ": " << dropReasonName(v.reason);
    EXPECT_FALSE(v.chunk.has_value());
  }
  masa::lcmt_rollout_chunk reordered = good;
  if (reordered.term_names.size() > 1) {
    std::swap(reordered.term_names[0], reordered.term_names[1]);
    EXPECT_EQ(assembler.accept(reordered).reason, DropReason::kWrongTerms) << "the order names the columns too";
  }
  EXPECT_TRUE(assembler.accept(good)) << "nothing of the dropped ones marked the chunk as seen";
  EXPECT_EQ(assembler.stats()[DropReason::kWrongTerms], reordered.term_names.size() > 1 ? 4 : 3);
}

}  // namespace
}  // namespace masa::transport
