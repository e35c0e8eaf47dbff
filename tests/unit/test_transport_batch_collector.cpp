#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "learner/intake/batch_collector.hpp"
#include "learner/intake/rollout_assembler.hpp"
#include "learner/intake/round_tracker.hpp"
#include "actors/rollout_chunker.hpp"
#include "test_transport_support.hpp"

namespace masa::transport {
namespace {

// The actors' chunking and the learner's intake, tested against each other and the wire.
using namespace masa::actor;
using namespace masa::learner;

using testing::fillRandomRollout;
using testing::RolloutShape;

constexpr RolloutShape kShape{6, 4, 5, 2};  // 6 envs x 4 steps, tiny dims
constexpr int64_t kCollectorRun = 3;

// Feeds rollouts of one actor through a real assembler into the collector under test.
class Feeder {
 public:
  explicit Feeder(int lag) : assembler_(config(lag)) {}
  static AssemblerConfig config(int lag) {
    AssemblerConfig c;
    c.run_id = kCollectorRun;
    c.horizon = kShape.horizon;
    c.obs_dim = kShape.obs_dim;
    c.act_dim = kShape.act_dim;
    c.max_policy_lag = lag;
    c.warn_interval_s = -1;
    return c;
  }
  void setLearnerVersion(int64_t v) { assembler_.setLearnerVersion(v); }
  // Sends one rollout acted with `version`; returns the chunks accepted. Without events the
  // rollout goes out as 3 chunks of 2 environments.
  int send(BatchCollector& collector, int64_t version, double event_prob = 0.0) {
    fillRandomRollout(rollout_, kShape, seq_, event_prob);
    const int budget = RolloutChunker::emptyChunkBytes(kShape.act_dim, rollout_.term_names) +
                       2 * RolloutChunker::envBytes(kShape.horizon, kShape.obs_dim, kShape.act_dim) + 100 +
                       (event_prob > 0 ? 2000 : 0);
    RolloutChunker chunker(budget);
    int accepted = 0;
    for (const auto& c : chunker.split(rollout_, {kCollectorRun, 0, seq_++, version})) {
      const Verdict v = assembler_.accept(c);
      if (v) {
        collector.add(*v.chunk);
        ++accepted;
      }
    }
    return accepted;
  }
  const RolloutAssembler& assembler() const { return assembler_; }
  const rollout::Rollout& lastRollout() const { return rollout_; }

 private:
  RolloutAssembler assembler_;
  rollout::Rollout rollout_;
  int64_t seq_ = 0;
};

CollectorConfig batchCollectorConfig(int num_envs, int lag, int capacity = 0) {
  CollectorConfig c;
  c.num_envs = num_envs;
  c.horizon = kShape.horizon;
  c.obs_dim = kShape.obs_dim;
  c.act_dim = kShape.act_dim;
  c.max_policy_lag = lag;
  c.capacity_envs = capacity;
  c.term_names = {"forward_velocity", "alive"};
  return c;
}

TEST(BatchCollector, EmitsABatchOnlyOnceEnoughEnvironmentsArrived) {
  Feeder feeder(0);
  BatchCollector collector(batchCollectorConfig(10, 0));
  testing::TakenBatch batch(collector.config());
  EXPECT_EQ(feeder.send(collector, 0), 3);
  EXPECT_EQ(collector.bufferedEnvs(), 6);
  EXPECT_FALSE(collector.ready());
  EXPECT_FALSE(take(collector, batch));
  EXPECT_EQ(feeder.send(collector, 0), 3);
  ASSERT_TRUE(collector.ready());
  ASSERT_TRUE(take(collector, batch));
  EXPECT_EQ(batch.data().num_envs, 10);
  EXPECT_EQ(batch.data().horizon, kShape.horizon);
  EXPECT_EQ(collector.bufferedEnvs(), 2);  // the rest waits for the next batch
  EXPECT_EQ(collector.stats().batches, 1);
  // Arrival order: the first rollout's six environments, then four of the second.
  for (int b = 0; b < 6; ++b) EXPECT_EQ(batch.origin.env_index[b], b);
  for (int b = 6; b < 10; ++b) EXPECT_EQ(batch.origin.env_index[b], b - 6);
}

TEST(BatchCollector, LagZeroIsStrictlyOnPolicy) {
  Feeder feeder(0);
  BatchCollector collector(batchCollectorConfig(6, 0));
  feeder.setLearnerVersion(2);
  collector.setLearnerVersion(2);
  EXPECT_EQ(feeder.send(collector, 1), 0);  // one version behind: refused at the gate
  EXPECT_EQ(feeder.assembler().stats()[DropReason::kTooOld], 3);
  EXPECT_EQ(feeder.send(collector, 2), 3);
  EXPECT_TRUE(collector.ready());
  // The learner updates before taking them: they are now one version stale and are evicted.
  collector.setLearnerVersion(3);
  EXPECT_EQ(collector.bufferedEnvs(), 0);
  EXPECT_EQ(collector.stats().envs_stale, 6);
  EXPECT_FALSE(collector.ready());
}

TEST(BatchCollector, LagTwoMixesVersionsOldestFirstAndEvictsBeyondTheLag) {
  Feeder feeder(2);
  BatchCollector collector(batchCollectorConfig(6, 2, /*capacity=*/24));
  feeder.setLearnerVersion(4);
  collector.setLearnerVersion(4);
  EXPECT_EQ(feeder.send(collector, 4), 3);
  EXPECT_EQ(feeder.send(collector, 2), 3);
  EXPECT_EQ(feeder.send(collector, 1), 0);  // three behind
  EXPECT_EQ(feeder.send(collector, 3), 3);
  testing::TakenBatch batch(collector.config());
  ASSERT_TRUE(take(collector, batch));
  EXPECT_EQ(batch.origin.env_version, std::vector<int64_t>({2, 2, 2, 2, 2, 2}));
  // Versions 3 and 4 remain; moving to 6 leaves only version 4 within the lag.
  collector.setLearnerVersion(6);
  EXPECT_EQ(collector.bufferedEnvs(), 6);
  EXPECT_EQ(collector.stats().envs_stale, 6);
  ASSERT_TRUE(take(collector, batch));
  EXPECT_EQ(batch.origin.env_version, std::vector<int64_t>(6, 4));
}

TEST(BatchCollector, FullPoolMakesRoomByEvictingOlderVersionsOnly) {
  Feeder feeder(5);
  BatchCollector collector(batchCollectorConfig(6, 5, /*capacity=*/6));
  feeder.setLearnerVersion(5);
  collector.setLearnerVersion(5);
  feeder.send(collector, 3);
  feeder.send(collector, 3);  // pool full of version 3: these six cannot enter
  EXPECT_EQ(collector.stats().envs_overflow, 6);
  feeder.send(collector, 5);  // newer: replaces the version-3 environments
  EXPECT_EQ(collector.stats().envs_overflow, 12);
  testing::TakenBatch batch(collector.config());
  ASSERT_TRUE(take(collector, batch));
  EXPECT_EQ(batch.origin.env_version, std::vector<int64_t>(6, 5));
}

TEST(BatchCollector, EpisodesAndTruncationsFollowTheirEnvironmentIntoTheBatch) {
  Feeder feeder(0);
  BatchCollector collector(batchCollectorConfig(6, 0));
  feeder.send(collector, 0, 0.3);
  testing::TakenBatch batch(collector.config());
  ASSERT_TRUE(take(collector, batch));
  const rollout::Rollout& d = batch.data();
  ASSERT_GT(d.numFinal(), 0);
  ASSERT_GE(d.numEpisodes(), d.numFinal());
  int truncated = 0;
  for (uint8_t x : d.truncated) truncated += x;
  EXPECT_EQ(truncated, d.numFinal());
  for (int i = 0; i < d.numFinal(); ++i) EXPECT_EQ(d.truncated[d.final_index[i]], 1);
  for (int i = 0; i < d.numEpisodes(); ++i) {
    EXPECT_GE(d.episode_env[i], 0);
    EXPECT_LT(d.episode_env[i], 6);
  }
  EXPECT_EQ(d.episode_term_sums.size(), static_cast<std::size_t>(d.numEpisodes()) * 2);
}

// The truncations (step, observation) and episodes (env, return, length, success, terms) of a
// rollout, in a canonical order: a batch must carry exactly those of the rollout it came from.
using Events = std::vector<std::vector<float>>;
Events eventsOf(const rollout::Rollout& r) {
  Events out;
  for (int i = 0; i < r.numFinal(); ++i) {
    std::vector<float> f{0.0f, static_cast<float>(r.final_index[i])};
    f.insert(f.end(), r.finalObs(i), r.finalObs(i) + r.obs_dim);
    out.push_back(f);
  }
  const int K = r.numTerms();
  for (int i = 0; i < r.numEpisodes(); ++i) {
    std::vector<float> ep{1.0f, static_cast<float>(r.episode_env[i]), r.episode_return[i],
                          static_cast<float>(r.episode_length[i]), static_cast<float>(r.episode_success[i])};
    ep.insert(ep.end(), &r.episode_term_sums[static_cast<std::size_t>(i) * K],
              &r.episode_term_sums[static_cast<std::size_t>(i) * K] + K);
    out.push_back(ep);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Slots are reused after a batch is taken and when a newer environment evicts an older one; the
// events of a slot's previous environment must not follow the new one into a batch.
TEST(BatchCollector, ReusedSlotsCarryOnlyTheEventsOfTheirNewEnvironments) {
  Feeder feeder(5);
  feeder.setLearnerVersion(5);  // versions 0..5 are all fresh enough
  BatchCollector collector(batchCollectorConfig(6, 5, /*capacity=*/12));
  collector.setLearnerVersion(5);
  testing::TakenBatch batch(collector.config());
  feeder.send(collector, 0, 0.3);
  const Events first = eventsOf(feeder.lastRollout());
  feeder.send(collector, 0, 0.3);
  const Events second = eventsOf(feeder.lastRollout());
  ASSERT_FALSE(first.empty());
  ASSERT_TRUE(take(collector, batch));
  EXPECT_EQ(eventsOf(batch.data()), first);
  feeder.send(collector, 1, 0.3);  // into the slots the first batch freed
  const Events third = eventsOf(feeder.lastRollout());
  ASSERT_TRUE(take(collector, batch));
  EXPECT_EQ(eventsOf(batch.data()), second);
  ASSERT_TRUE(take(collector, batch));
  EXPECT_EQ(eventsOf(batch.data()), third);
  batch.buffer.checkFinalObs();

  // Eviction: a full pool of version 2 gives its slots to version 3.
  BatchCollector full(batchCollectorConfig(6, 5, /*capacity=*/6));
  full.setLearnerVersion(5);
  feeder.send(full, 2, 0.3);
  feeder.send(full, 3, 0.3);
  const Events newer = eventsOf(feeder.lastRollout());
  EXPECT_EQ(full.stats().envs_overflow, 6);
  ASSERT_TRUE(take(full, batch));
  EXPECT_EQ(eventsOf(batch.data()), newer);
  batch.buffer.checkFinalObs();
}

// A batch short of lost environments: at least min_envs buffered are taken whole (episodes and
// truncations with them), the buffer shrinks to them, and the next full batch grows it back.
TEST(BatchCollector, TakeShortTakesWhatArrivedOnceEnoughDid) {
  Feeder feeder(0);
  BatchCollector collector(batchCollectorConfig(10, 0));
  testing::TakenBatch batch(collector.config());
  feeder.send(collector, 0, 0.3);  // 6 environments, with events
  EXPECT_FALSE(collector.takeShort(batch.buffer, 7, &batch.origin)) << "fewer than min_envs";
  EXPECT_EQ(collector.bufferedEnvs(), 6);
  ASSERT_TRUE(collector.takeShort(batch.buffer, 5, &batch.origin));
  EXPECT_EQ(batch.buffer.numEnvs(), 6);
  EXPECT_EQ(batch.buffer.size(), 6 * kShape.horizon);
  EXPECT_EQ(collector.bufferedEnvs(), 0);
  EXPECT_EQ(collector.stats().short_batches, 1);
  EXPECT_EQ(eventsOf(batch.data()), eventsOf(feeder.lastRollout())) << "the rollout's events, in its own columns";
  batch.buffer.checkFinalObs();
  for (int b = 0; b < 6; ++b) EXPECT_EQ(batch.origin.env_index[b], b);

  feeder.send(collector, 0);
  feeder.send(collector, 0);
  ASSERT_TRUE(collector.takeShort(batch.buffer, 5, &batch.origin)) << "a full batch is never short";
  EXPECT_EQ(batch.buffer.numEnvs(), 10);
  EXPECT_EQ(collector.stats().short_batches, 1);
  EXPECT_EQ(collector.bufferedEnvs(), 2);
}

using TrackerClock = RoundTracker::Clock;
constexpr auto kMs = std::chrono::milliseconds(1);

// Two actors with 4 chunks per rollout; the learner has just updated once.
RoundTracker trackerAfterAFullRound(TrackerClock::time_point t0) {
  RoundTracker r(0.010);
  for (int actor = 0; actor < 2; ++actor)
    for (int c = 0; c < 4; ++c) r.chunkArrived(actor, 0, c, 4, t0);
  r.newRound();
  return r;
}

TEST(RoundTracker, TheFirstRoundNeverSettlesNobodyIsKnownYet) {
  const auto t0 = TrackerClock::now();
  RoundTracker r(0.010);
  for (int c = 0; c < 3; ++c) r.chunkArrived(0, 0, c, 4, t0);
  EXPECT_FALSE(r.settled(t0 + 1000 * kMs));
}

TEST(RoundTracker, ALostChunkIsKnownWhenItsRolloutsLastChunkComes) {
  const auto t0 = TrackerClock::now();
  RoundTracker r = trackerAfterAFullRound(t0);
  for (int c : {0, 1, 3}) r.chunkArrived(0, 1, c, 4, t0 + 5 * kMs);  // chunk 2 lost
  EXPECT_FALSE(r.settled(t0 + 5 * kMs)) << "actor 1 has not delivered yet";
  EXPECT_FALSE(r.settled(t0 + 500 * kMs)) << "however long: a slow actor's rollout is worth waiting for";
  for (int c = 0; c < 4; ++c) r.chunkArrived(1, 1, c, 4, t0 + 6 * kMs);
  EXPECT_TRUE(r.settled(t0 + 6 * kMs));
  EXPECT_EQ(r.nextDeadline(), TrackerClock::time_point::max());
}

TEST(RoundTracker, ALostLastChunkIsKnownAfterTheGrace) {
  const auto t0 = TrackerClock::now();
  RoundTracker r = trackerAfterAFullRound(t0);
  for (int c = 0; c < 4; ++c) r.chunkArrived(1, 1, c, 4, t0 + 5 * kMs);
  for (int c : {0, 1, 2}) r.chunkArrived(0, 1, c, 4, t0 + 7 * kMs);  // chunk 3 lost
  EXPECT_EQ(r.nextDeadline(), t0 + 17 * kMs);
  EXPECT_FALSE(r.settled(t0 + 16 * kMs));
  EXPECT_TRUE(r.settled(t0 + 17 * kMs));
  r.chunkArrived(0, 1, 3, 4, t0 + 12 * kMs);  // it came after all, within the grace
  EXPECT_TRUE(r.settled(t0 + 12 * kMs));
}

TEST(RoundTracker, AnActorSilentForAWholeRoundIsNoLongerWaitedFor) {
  const auto t0 = TrackerClock::now();
  RoundTracker r = trackerAfterAFullRound(t0);
  for (int c = 0; c < 4; ++c) r.chunkArrived(0, 1, c, 4, t0 + 5 * kMs);
  EXPECT_FALSE(r.settled(t0 + 5 * kMs)) << "actor 1 delivered last round";
  r.newRound();  // the batch formed anyway (actor 0's next rollout filled it)
  for (int c = 0; c < 3; ++c) r.chunkArrived(0, 2, c, 4, t0 + 9 * kMs);
  EXPECT_TRUE(r.settled(t0 + 20 * kMs)) << "actor 1 is dead or far behind; actor 0's last chunk was lost";
  // A newer rollout of an actor replaces its older one in the round.
  r.chunkArrived(0, 3, 0, 4, t0 + 21 * kMs);
  EXPECT_FALSE(r.settled(t0 + 21 * kMs));
}

}  // namespace
}  // namespace masa::transport
