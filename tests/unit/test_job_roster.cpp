// The roster of a signed MPI job (common/transport/job_roster.hpp): built by every process from the
// public keys gathered over MPI. Here the gather is a function that hands back the other processes'
// records around this one's, as MPI_Allgather would in world-rank order.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "common/integrity/ed25519_keys.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/job_roster.hpp"
#include "common/transport/message_sign.hpp"

namespace masa::transport {
namespace {

// A job of 2 learner ranks and 3 actors; `me` is one of them, whose record the gather puts in its
// place; the others' keys are new ones.
struct Job {
  std::vector<SenderId> ids = {{Role::kLearner, 0}, {Role::kLearner, 1}, {Role::kActor, 0}, {Role::kActor, 1},
                               {Role::kActor, 2}};
  std::vector<integrity::PublicKeyBytes> keys;
  Job() {
    for (std::size_t i = 0; i < ids.size(); ++i) keys.push_back(integrity::SigningKey::generate().publicKey());
  }
  std::vector<uint8_t> records() const {
    std::vector<uint8_t> all;
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const auto r = jobKeyRecord(ids[i], keys[i]);
      all.insert(all.end(), r.begin(), r.end());
    }
    return all;
  }
  GatherAll gatherAs(SenderId me) const {
    return [this, me](const std::vector<uint8_t>& mine) {
      std::vector<uint8_t> all;
      for (std::size_t i = 0; i < ids.size(); ++i) {
        const auto r = ids[i] == me ? mine : jobKeyRecord(ids[i], keys[i]);
        all.insert(all.end(), r.begin(), r.end());
      }
      return all;
    };
  }
};

// Seals `message` with `signer` for `channel` and returns what a receiver with `roster` concludes.
WireVerdict verdictOf(MessageSigner& signer, const Roster& roster, const std::string& channel) {
  std::vector<uint8_t> wire = {1, 2, 3, 4, 5, 6, 7, 8};
  const int size = static_cast<int>(wire.size());
  wire.resize(wire.size() + kSigTrailerBytes);
  signer.seal(channel, wire.data(), size, wire.data() + size);
  MessageVerifier verifier(std::make_shared<Roster>(roster), 0);
  return verifier.open(channel, wire.data(), static_cast<int>(wire.size())).verdict;
}

TEST(JobRoster, ListsLearnerZeroAndTheActorsOnTheirChannelsAndNotTheOtherRanks) {
  const Job job;
  const Roster roster = jobRoster(job.records());
  ASSERT_EQ(roster.entries().size(), 4u);
  const Roster::Entry* learner = roster.find({Role::kLearner, 0});
  ASSERT_NE(learner, nullptr);
  EXPECT_EQ(learner->key, job.keys[0]);
  EXPECT_EQ(learner->channels, defaultChannels(Role::kLearner));
  EXPECT_EQ(roster.find({Role::kLearner, 1}), nullptr) << "a rank above 0 publishes nothing over LCM";
  for (uint32_t a = 0; a < 3; ++a) {
    const Roster::Entry* actor = roster.find({Role::kActor, a});
    ASSERT_NE(actor, nullptr);
    EXPECT_EQ(actor->key, job.keys[2 + a]);
    EXPECT_EQ(actor->channels, defaultChannels(Role::kActor));
  }
  EXPECT_NE(roster.format().find("actor 2 "), std::string::npos);
}

TEST(JobRoster, AnActorsKeyMadeInMemorySignsItsRolloutsAndCannotSignParameters) {
  const Job job;
  SignedMode mode = jobSignedMode({Role::kActor, 1}, job.gatherAs({Role::kActor, 1}));
  ASSERT_NE(mode.signer, nullptr);
  EXPECT_EQ(mode.signer->id(), (SenderId{Role::kActor, 1}));
  EXPECT_EQ(mode.roster->find({Role::kActor, 1})->key, mode.signer->publicKey()) << "the roster has its own key";
  EXPECT_EQ(verdictOf(*mode.signer, *mode.roster, kRolloutChannel), WireVerdict::kOk);
  EXPECT_EQ(verdictOf(*mode.signer, *mode.roster, kPolicyChannel), WireVerdict::kNotPermitted);
  // Learner rank 0 signs parameters; a second job's processes (new keys) are strangers to this one.
  SignedMode learner = jobSignedMode({Role::kLearner, 0}, job.gatherAs({Role::kLearner, 0}));
  EXPECT_EQ(verdictOf(*learner.signer, *learner.roster, kPolicyChannel), WireVerdict::kOk);
  EXPECT_EQ(verdictOf(*learner.signer, *mode.roster, kPolicyChannel), WireVerdict::kUnauthenticated)
      << "the actor's roster has learner 0 with the key of another process";
}

TEST(JobRoster, ALearnerRankAboveZeroOnlyVerifies) {
  const Job job;
  const SignedMode mode = jobSignedMode({Role::kLearner, 1}, job.gatherAs({Role::kLearner, 1}));
  EXPECT_EQ(mode.signer, nullptr);
  ASSERT_NE(mode.roster, nullptr);
  EXPECT_EQ(mode.roster->entries().size(), 4u);
}

TEST(JobRoster, MalformedGathersAndASenderTwiceAreRefusedNamingTheJobAndTheProcess) {
  const Job job;
  auto refused = [](const std::vector<uint8_t>& records, const std::string& expected) {
    try {
      jobRoster(records);
      ADD_FAILURE() << "accepted; expected: " << expected;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("roster of the MPI job"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  std::vector<uint8_t> records = job.records();
  refused({}, "0 bytes are not whole records");
  refused(std::vector<uint8_t>(records.begin(), records.end() - 1), "not whole records");
  std::vector<uint8_t> runner = records;
  runner[2 * kJobKeyRecordBytes] = static_cast<uint8_t>(Role::kRunner);
  refused(runner, "process 2 has role byte 3, neither learner nor actor");
  // Process 3 says it is actor 0 too: whichever key the roster kept, one of them would be believed
  // for the other.
  std::vector<uint8_t> twice = records;
  twice[3 * kJobKeyRecordBytes + 4] = 0;
  refused(twice, "process 3: actor 0 is in the roster twice");
}

}  // namespace
}  // namespace masa::transport
