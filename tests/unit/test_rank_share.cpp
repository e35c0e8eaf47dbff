// In an MPI job actor i reports to learner rank i mod ranks (issue #55, item 3): each rank takes
// rollouts only from its own share. A chunk signed by an actor of rank 1, copied to rank 0's URL,
// verifies there (the signature names the channel, not the rank); rank 0 must refuse it, count it
// (another_ranks_actor) and let it move no counter window, while rank 1 takes the original.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "common/integrity/ed25519_keys.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/message_sign.hpp"
#include "common/transport/roster.hpp"
#include "common/transport/transport.hpp"

namespace masa::transport {
namespace {

namespace fs = std::filesystem;

TEST(RankShare, AChunkOfAnotherRanksActorCopiedToThisRanksUrlIsRefusedAndCounted) {
  const fs::path dir = fs::temp_directory_path() / ("masa_test_rank_share_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  auto roster = std::make_shared<Roster>();
  std::vector<std::shared_ptr<MessageSigner>> actors;
  for (uint32_t a = 0; a < 4; ++a) {
    const std::string stem = (dir / ("actor" + std::to_string(a))).string();
    roster->add({Role::kActor, a}, integrity::generateKeyPair(stem + ".key", stem + ".pub"), defaultChannels(Role::kActor));
    actors.push_back(MessageSigner::load(stem + ".key", {Role::kActor, a}, *roster));
  }
  // Two learner ranks of one job, each on its own URL (here: its own in-process bus).
  Transport rank0("memq://", SignedMode{nullptr, roster, ActorShare{0, 2}});
  Transport rank1("memq://", SignedMode{nullptr, roster, ActorShare{1, 2}});
  int taken0 = 0, taken1 = 0;
  rank0.subscribeRaw(kRolloutChannel, [&](const void*, int) { ++taken0; });
  rank1.subscribeRaw(kRolloutChannel, [&](const void*, int) { ++taken1; });
  const std::vector<uint8_t> body(64, 0x5a);
  auto signedChunk = [&](MessageSigner& signer) {
    std::vector<uint8_t> b(body);
    b.resize(body.size() + kSigTrailerBytes);
    signer.seal(kRolloutChannel, b.data(), static_cast<int>(body.size()), b.data() + body.size());
    return b;
  };
  auto send = [](Transport& to, const std::vector<uint8_t>& b) {
    ASSERT_TRUE(to.publishWire(kRolloutChannel, b.data(), static_cast<int>(b.size())));
    for (int i = 0; i < 3; ++i) to.handleTimeout(5);
  };
  const std::vector<uint8_t> for_rank1 = signedChunk(*actors[1]);
  send(rank0, for_rank1);  // copied to rank 0's port
  EXPECT_EQ(taken0, 0) << "rank 0 took actor 1's chunk: " << rank0.rejectSummary();
  EXPECT_EQ(rank0.rejected(kRolloutChannel)[static_cast<int>(WireVerdict::kAnotherRanksActor)], 1) << rank0.rejectSummary();
  send(rank1, for_rank1);  // where it was sent
  EXPECT_EQ(taken1, 1) << rank1.rejectSummary();
  send(rank0, signedChunk(*actors[0]));
  send(rank0, signedChunk(*actors[2]));
  send(rank0, signedChunk(*actors[3]));
  EXPECT_EQ(taken0, 2) << "rank 0 takes actors 0 and 2 only: " << rank0.rejectSummary();
  EXPECT_EQ(rank0.rejected(kRolloutChannel)[static_cast<int>(WireVerdict::kAnotherRanksActor)], 2);
  // One learner rank (the default share) takes every actor.
  Transport alone("memq://", SignedMode{nullptr, roster, {}});
  int taken = 0;
  alone.subscribeRaw(kRolloutChannel, [&](const void*, int) { ++taken; });
  for (const auto& a : actors) send(alone, signedChunk(*a));
  EXPECT_EQ(taken, 4) << alone.rejectSummary();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace masa::transport
