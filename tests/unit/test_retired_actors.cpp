// A run resumed with fewer actors (issue #55, item 3): the actors it no longer runs leave its
// roster (Roster::withoutActorsFrom; masa_roster make --actors K, which deploy/train.sh runs on
// --resume), so a chunk signed with a retired actor's key, recorded or sent by the host that still
// holds it, is refused by the learner as an unknown sender, counted, and moves nothing.
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

TEST(RetiredActors, AChunkSignedByAnActorTheResumedRunNoLongerHasIsRefusedAsUnknownSender) {
  const fs::path dir = fs::temp_directory_path() / ("masa_test_retired_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  // The run as it started: a learner and 4 actors.
  Roster four;
  four.add({Role::kLearner, 0}, integrity::generateKeyPair((dir / "learner0.key").string(), (dir / "learner0.pub").string()),
           defaultChannels(Role::kLearner));
  std::vector<std::shared_ptr<MessageSigner>> actors;
  for (uint32_t a = 0; a < 4; ++a) {
    const std::string stem = (dir / ("actor" + std::to_string(a))).string();
    four.add({Role::kActor, a}, integrity::generateKeyPair(stem + ".key", stem + ".pub"), defaultChannels(Role::kActor));
    actors.push_back(MessageSigner::load(stem + ".key", {Role::kActor, a}, four));
  }
  // Resumed with 2 actors.
  std::vector<SenderId> retired;
  auto two = std::make_shared<Roster>(four.withoutActorsFrom(2, retired));
  ASSERT_EQ(retired, (std::vector<SenderId>{{Role::kActor, 2}, {Role::kActor, 3}}));
  ASSERT_EQ(two->entries().size(), 3u);
  EXPECT_EQ(two->find({Role::kActor, 3}), nullptr);
  EXPECT_NE(two->find({Role::kActor, 1}), nullptr);

  Transport learner("memq://", SignedMode{nullptr, two, {}});
  int taken = 0;
  learner.subscribeRaw(kRolloutChannel, [&](const void*, int) { ++taken; });
  const std::vector<uint8_t> body(64, 0x5a);  // not a chunk: what the roster decides comes first
  auto send = [&](MessageSigner& signer) {
    std::vector<uint8_t> b(body);
    b.resize(body.size() + kSigTrailerBytes);
    signer.seal(kRolloutChannel, b.data(), static_cast<int>(body.size()), b.data() + body.size());
    ASSERT_TRUE(learner.publishWire(kRolloutChannel, b.data(), static_cast<int>(b.size())));
    for (int i = 0; i < 3; ++i) learner.handleTimeout(5);
  };
  send(*actors[3]);
  send(*actors[2]);
  EXPECT_EQ(taken, 0) << "a retired actor's chunk was taken: " << learner.rejectSummary();
  EXPECT_EQ(learner.rejected(kRolloutChannel)[static_cast<int>(WireVerdict::kUnknownSender)], 2) << learner.rejectSummary();
  send(*actors[1]);
  EXPECT_EQ(taken, 1) << "an actor the run still has: " << learner.rejectSummary();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace masa::transport
