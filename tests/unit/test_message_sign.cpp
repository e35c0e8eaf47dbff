// A key per role, permissions per channel, counters (issue #33, item 2; common/transport/message_sign.hpp):
// the roster file, the anti-replay window, the SIG1 trailer alone, and through the processes that
// receive: actors refuse parameters signed by an actor's key, the learner refuses a chunk signed by
// one actor that claims another, and a replayed valid message is refused; each counted by reason,
// none leaving a trace in what the receiver does next.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "actors/actor.hpp"
#include "actors/rollout_chunker.hpp"
#include "common/config/run_config.hpp"
#include "common/integrity/ed25519_keys.hpp"
#include "common/model/method.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/message_sign.hpp"
#include "common/transport/roster.hpp"
#include "common/transport/transport.hpp"
#include "learner/learner.hpp"
#include "learner/ppo_algorithm.hpp"
#include "masa/lcmt_policy_params.hpp"
#include "masa/lcmt_rollout_chunk.hpp"
#include "test_transport_support.hpp"

namespace masa::transport {
namespace {

namespace fs = std::filesystem;
using testing::encode;
using testing::samplePolicy;

fs::path freshSignDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("masa_test_sign_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A run of a learner and `actors` actors: a key each (in a temporary directory), the roster, and a
// signer per sender.
struct SignedRun {
  fs::path dir;
  std::shared_ptr<Roster> roster = std::make_shared<Roster>();
  std::shared_ptr<MessageSigner> learner;
  std::vector<std::shared_ptr<MessageSigner>> actors;

  explicit SignedRun(int num_actors, const std::string& name = "run") : dir(freshSignDir(name)) {
    std::vector<std::pair<SenderId, fs::path>> keys;
    keys.push_back({{Role::kLearner, 0}, dir / "learner0"});
    for (int a = 0; a < num_actors; ++a) keys.push_back({{Role::kActor, static_cast<uint32_t>(a)}, dir / ("actor" + std::to_string(a))});
    for (const auto& [id, stem] : keys)
      roster->add(id, integrity::generateKeyPair(stem.string() + ".key", stem.string() + ".pub"), defaultChannels(id.role));
    learner = MessageSigner::load((dir / "learner0.key").string(), {Role::kLearner, 0}, *roster);
    for (int a = 0; a < num_actors; ++a)
      actors.push_back(MessageSigner::load((dir / ("actor" + std::to_string(a) + ".key")).string(),
                                           {Role::kActor, static_cast<uint32_t>(a)}, *roster));
  }
  ~SignedRun() { fs::remove_all(dir); }
  SignedMode as(const std::shared_ptr<MessageSigner>& who) const { return {who, roster, {}}; }
};

// `message` with the SIG1 trailer of `signer` for `channel` (its next counter).
std::vector<uint8_t> signedBytes(MessageSigner& signer, const std::string& channel, const std::vector<uint8_t>& message) {
  std::vector<uint8_t> out(message);
  out.resize(message.size() + kSigTrailerBytes);
  signer.seal(channel, message.data(), static_cast<int>(message.size()), out.data() + message.size());
  return out;
}

int64_t count(const Transport& t, const std::string& channel, WireVerdict v) {
  return t.rejected(channel)[static_cast<int>(v)];
}

// ---------------------------------------------------------------------------------------------
// The roster file.

TEST(Roster, WrittenAndReadBackTheSameAndRefusedWhenOthersMayWriteIt) {
  SignedRun run(2, "roster");
  const fs::path path = run.dir / "roster";
  std::ofstream(path) << run.roster->format();
  ::chmod(path.c_str(), 0644);
  const Roster back = Roster::load(path.string());
  ASSERT_EQ(back.entries().size(), 3u);
  for (const auto& e : run.roster->entries()) {
    const Roster::Entry* b = back.find(e.id);
    ASSERT_NE(b, nullptr) << e.id.name();
    EXPECT_EQ(b->key, e.key);
    EXPECT_EQ(b->channels, e.channels);
  }
  EXPECT_TRUE(Roster::permits(*back.find({Role::kLearner, 0}), kPolicyChannel));
  EXPECT_FALSE(Roster::permits(*back.find({Role::kActor, 1}), kPolicyChannel));
  EXPECT_EQ(back.find({Role::kActor, 2}), nullptr);
  ::chmod(path.c_str(), 0666);
  try {
    Roster::load(path.string());
    FAIL() << "a roster others may write was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("others may write it"), std::string::npos) << e.what();
  }
}

TEST(Roster, AMalformedLineIsRefusedWithItsLineNumber) {
  const std::string key(64, 'a');
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"pilot 0 " + key + " MASA_POLICY\n", "unknown role"},
      {"actor x " + key + " MASA_ROLLOUT\n", "not a number"},
      {"actor 0 abc MASA_ROLLOUT\n", "64 hex digits"},
      {"actor 0 " + std::string(64, 'g') + " MASA_ROLLOUT\n", "64 hex digits"},
      {"actor 0 " + key + "\n", "expected"},
      {"actor 0 " + key + " MASA_ROLLOUT,,MASA_ACTOR_HEARTBEAT\n", "empty channel"},
      {"# nothing\n", "lists no sender"},
  };
  for (const auto& [text, why] : bad) {
    try {
      Roster::parse("# a comment\n" + text, "test");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  }
  // A sender twice: whichever line a receiver took, the other would be a second key.
  SignedRun run(1, "twice");
  const std::string line = run.roster->format().substr(run.roster->format().find("actor 0"));
  EXPECT_THROW(Roster::parse(run.roster->format() + line, "test"), std::runtime_error);
}

TEST(Roster, ASigningKeyTheRosterDoesNotGiveThatSenderIsRefused) {
  SignedRun run(2, "wrongkey");
  EXPECT_THROW(MessageSigner::load((run.dir / "actor1.key").string(), {Role::kActor, 0}, *run.roster), std::runtime_error);
  EXPECT_THROW(MessageSigner::load((run.dir / "actor0.key").string(), {Role::kActor, 5}, *run.roster), std::runtime_error);
}

// ---------------------------------------------------------------------------------------------
// The anti-replay window.

TEST(ReplayWindow, TakesEachCounterOnceInAnyOrderWithinTheWindowAndNothingBelowIt) {
  constexpr uint64_t k = 10000;
  ReplayWindow w;
  EXPECT_EQ(w.check(k), WireVerdict::kOk);
  w.accept(k);
  EXPECT_EQ(w.check(k), WireVerdict::kReplayed);
  EXPECT_EQ(w.check(k + 1), WireVerdict::kOk);
  EXPECT_EQ(w.check(k - 1), WireVerdict::kOk) << "reordered, never seen";
  w.accept(k + 5);
  EXPECT_EQ(w.check(k), WireVerdict::kReplayed) << "still seen after the window moved";
  EXPECT_EQ(w.check(k + 3), WireVerdict::kOk);
  w.accept(k + 3);
  EXPECT_EQ(w.check(k + 3), WireVerdict::kReplayed);
  EXPECT_EQ(w.check(k + 5 - kReplayWindow + 1), WireVerdict::kOk) << "the oldest counter the window holds";
  EXPECT_EQ(w.check(k + 5 - kReplayWindow), WireVerdict::kBeyondWindow);
  EXPECT_EQ(w.check(0), WireVerdict::kBeyondWindow);
  // A jump past the whole window: everything below the new window is beyond it, the new top taken.
  const uint64_t jump = k + 5 + 5 * kReplayWindow;
  w.accept(jump);
  EXPECT_EQ(w.check(k + 5), WireVerdict::kBeyondWindow);
  EXPECT_EQ(w.check(jump - 1), WireVerdict::kOk);
  EXPECT_EQ(w.check(jump), WireVerdict::kReplayed);
  // Shifts by less than the window keep what was seen: k + 5 + 4 * window is seen once only.
  w.accept(jump - 7);
  w.accept(jump + 3);
  EXPECT_EQ(w.check(jump - 7), WireVerdict::kReplayed);
  EXPECT_EQ(w.check(jump), WireVerdict::kReplayed);
  EXPECT_EQ(w.check(jump + 2), WireVerdict::kOk);
}

// ---------------------------------------------------------------------------------------------
// The trailer alone.

TEST(MessageSign, ASignedMessageOpensForItsSenderOnItsChannelAndEveryChangeIsRefusedByReason) {
  SignedRun run(2, "trailer");
  MessageVerifier verifier(run.roster, 0);
  const std::vector<uint8_t> message = encode(samplePolicy());
  const std::vector<uint8_t> bytes = signedBytes(*run.learner, kPolicyChannel, message);
  ASSERT_EQ(bytes.size(), message.size() + 81);
  EXPECT_EQ(std::memcmp(bytes.data() + message.size(), "SIG1", 4), 0);
  const OpenedMessage ok = verifier.open(kPolicyChannel, bytes.data(), static_cast<int>(bytes.size()));
  EXPECT_EQ(ok.verdict, WireVerdict::kOk);
  EXPECT_EQ(ok.size, static_cast<int>(message.size()));
  EXPECT_EQ(ok.sender, (SenderId{Role::kLearner, 0}));
  auto verdict = [&](const std::string& channel, const std::vector<uint8_t>& b) {
    return verifier.open(channel, b.data(), static_cast<int>(b.size())).verdict;
  };
  EXPECT_EQ(verdict(kLearnerStatsChannel, bytes), WireVerdict::kUnauthenticated) << "moved to another channel it may publish on";
  EXPECT_EQ(verdict(kPolicyChannel, message), WireVerdict::kUnauthenticated) << "unsigned";
  EXPECT_EQ(verifier.open(kPolicyChannel, nullptr, 0).verdict, WireVerdict::kUnauthenticated);
  // One flipped bit: in the message, the counter, the signature.
  for (std::size_t at : {std::size_t{0}, message.size() / 2, message.size() + 12, bytes.size() - 1}) {
    std::vector<uint8_t> flipped = bytes;
    flipped[at] ^= 0x01;
    EXPECT_EQ(verdict(kPolicyChannel, flipped), WireVerdict::kUnauthenticated) << "bit flipped at byte " << at;
  }
  // The sender field rewritten: to an actor (which may not publish parameters), to an unknown actor.
  std::vector<uint8_t> as_actor = bytes;
  as_actor[message.size() + 4] = static_cast<uint8_t>(Role::kActor);
  EXPECT_EQ(verdict(kPolicyChannel, as_actor), WireVerdict::kNotPermitted);
  as_actor[message.size() + 8] = 9;
  EXPECT_EQ(verdict(kPolicyChannel, as_actor), WireVerdict::kUnknownSender);
  std::vector<uint8_t> no_role = bytes;
  no_role[message.size() + 4] = 0;
  EXPECT_EQ(verdict(kPolicyChannel, no_role), WireVerdict::kUnauthenticated);
  // Signed by actor 1's key for its own rollouts, moved to actor 0's name: the signature fails.
  std::vector<uint8_t> chunkish = signedBytes(*run.actors[1], kRolloutChannel, message);
  chunkish[message.size() + 8] = 0;
  EXPECT_EQ(verdict(kRolloutChannel, chunkish), WireVerdict::kUnauthenticated);
}

// ---------------------------------------------------------------------------------------------
// Through the transport.

TEST(MessageSignTransport, ASignedMessageReachesEverySubscriptionOnceWithItsOriginalBytesAndTheSender) {
  SignedRun run(1, "bus");
  Transport bus("memq://", run.as(run.actors[0]));
  ASSERT_TRUE(bus.signs());
  std::vector<std::vector<uint8_t>> raw;
  std::vector<SenderId> senders;
  int typed = 0;
  bus.subscribeRaw(kPolicyChannel, [&](const void* data, int size) {
    raw.emplace_back(static_cast<const uint8_t*>(data), static_cast<const uint8_t*>(data) + size);
    senders.push_back(*bus.currentSender());
  });
  bus.subscribe<masa::lcmt_policy_params>(kPolicyChannel, [&](const masa::lcmt_policy_params&) { ++typed; });
  const std::vector<uint8_t> message = encode(samplePolicy());
  ASSERT_TRUE(bus.publishWire(kPolicyChannel, signedBytes(*run.learner, kPolicyChannel, message).data(),
                              static_cast<int>(message.size()) + kSigTrailerBytes));
  ASSERT_TRUE(bus.publishWire(kPolicyChannel, signedBytes(*run.learner, kPolicyChannel, message).data(),
                              static_cast<int>(message.size()) + kSigTrailerBytes));
  for (int i = 0; i < 5; ++i) bus.handleTimeout(10);
  ASSERT_EQ(raw.size(), 2u) << "two messages, each once, though both subscriptions see the same bytes";
  EXPECT_EQ(typed, 2);
  EXPECT_EQ(raw[0], message);
  EXPECT_EQ(senders[0], (SenderId{Role::kLearner, 0}));
  EXPECT_EQ(bus.decodeErrors(), 0) << bus.rejectSummary();
  EXPECT_FALSE(bus.currentSender().has_value()) << "only inside a handler";
}

// A watcher (masa_lcm_probe --roster) holds the roster and no key: it verifies as a member does and
// cannot publish, neither signed nor unsigned.
TEST(MessageSignTransport, AWatcherWithTheRosterVerifiesEveryMessageAndCannotPublish) {
  SignedRun run(1, "watcher");
  Transport bus("memq://", SignedMode{nullptr, run.roster, {}});
  EXPECT_TRUE(bus.authenticates());
  EXPECT_FALSE(bus.signs());
  int taken = 0;
  bus.subscribeRaw(kPolicyChannel, [&](const void*, int) { ++taken; });
  const std::vector<uint8_t> message = encode(samplePolicy());
  const int n = static_cast<int>(message.size()) + kSigTrailerBytes;
  ASSERT_TRUE(bus.publishWire(kPolicyChannel, signedBytes(*run.learner, kPolicyChannel, message).data(), n));
  ASSERT_TRUE(bus.publishWire(kPolicyChannel, signedBytes(*run.actors[0], kPolicyChannel, message).data(), n));
  ASSERT_TRUE(bus.publishWire(kPolicyChannel, message.data(), static_cast<int>(message.size())));
  for (int i = 0; i < 5; ++i) bus.handleTimeout(10);
  EXPECT_EQ(taken, 1) << "only the learner's parameters: " << bus.rejectSummary();
  EXPECT_EQ(count(bus, kPolicyChannel, WireVerdict::kNotPermitted), 1);
  EXPECT_EQ(count(bus, kPolicyChannel, WireVerdict::kUnauthenticated), 1);
  EXPECT_THROW(bus.publishRaw(kPolicyChannel, message.data(), static_cast<int>(message.size())), std::logic_error);
  EXPECT_THROW(bus.publish(kPolicyChannel, samplePolicy()), std::logic_error);
  EXPECT_THROW(Transport("memq://", SignedMode{run.learner, nullptr, {}}), std::invalid_argument);
}

TEST(MessageSignTransport, AReplayedValidMessageIsRefusedAndCountedAndOneFromBeyondTheWindowToo) {
  SignedRun run(1, "replay");
  Transport bus("memq://", run.as(run.actors[0]));
  int handled = 0;
  bus.subscribe<masa::lcmt_policy_params>(kPolicyChannel, [&](const masa::lcmt_policy_params&) { ++handled; });
  const std::vector<uint8_t> message = encode(samplePolicy());
  const std::vector<uint8_t> first = signedBytes(*run.learner, kPolicyChannel, message);
  auto send = [&](const std::vector<uint8_t>& b) {
    ASSERT_TRUE(bus.publishWire(kPolicyChannel, b.data(), static_cast<int>(b.size())));
    for (int i = 0; i < 3; ++i) bus.handleTimeout(10);
  };
  send(first);
  EXPECT_EQ(handled, 1);
  send(first);  // recorded off the LAN and sent again
  EXPECT_EQ(handled, 1) << "a replay reached the handler";
  EXPECT_EQ(count(bus, kPolicyChannel, WireVerdict::kReplayed), 1);
  // Newer messages move the window on; the first message's counter falls out of it.
  const uint64_t top = run.learner->nextCounter() + kReplayWindow;
  std::vector<uint8_t> newest(message);
  newest.resize(message.size() + kSigTrailerBytes);
  run.learner->sealWithCounter(kPolicyChannel, message.data(), static_cast<int>(message.size()), top, newest.data() + message.size());
  send(newest);
  EXPECT_EQ(handled, 2);
  std::vector<uint8_t> old(message);
  old.resize(message.size() + kSigTrailerBytes);
  run.learner->sealWithCounter(kPolicyChannel, message.data(), static_cast<int>(message.size()), top - kReplayWindow,
                               old.data() + message.size());
  send(old);  // a valid signature, never seen, but too far behind
  send(first);
  EXPECT_EQ(handled, 2);
  EXPECT_EQ(count(bus, kPolicyChannel, WireVerdict::kBeyondWindow), 2);
  // Within the window, out of order, never seen: taken once.
  std::vector<uint8_t> late(message);
  late.resize(message.size() + kSigTrailerBytes);
  run.learner->sealWithCounter(kPolicyChannel, message.data(), static_cast<int>(message.size()), top - 10, late.data() + message.size());
  send(late);
  send(late);
  EXPECT_EQ(handled, 3);
  EXPECT_EQ(count(bus, kPolicyChannel, WireVerdict::kReplayed), 2);
  EXPECT_NE(bus.rejectSummary().find("replayed 2"), std::string::npos) << bus.rejectSummary();
  fs::remove_all(run.dir);
}

TEST(MessageSignTransport, ARefusedMessageLeavesNoTraceInTheWindow) {
  // A message whose signature fails, with a counter far ahead, must not move the window: the
  // sender's real next message is still taken.
  SignedRun run(1, "notrace");
  Transport bus("memq://", run.as(run.actors[0]));
  int handled = 0;
  bus.subscribe<masa::lcmt_policy_params>(kPolicyChannel, [&](const masa::lcmt_policy_params&) { ++handled; });
  const std::vector<uint8_t> message = encode(samplePolicy());
  std::vector<uint8_t> forged(message);
  forged.resize(message.size() + kSigTrailerBytes);
  run.learner->sealWithCounter(kPolicyChannel, message.data(), static_cast<int>(message.size()),
                               run.learner->nextCounter() + 100 * kReplayWindow, forged.data() + message.size());
  forged[10] ^= 0x40;  // changed after signing
  ASSERT_TRUE(bus.publishWire(kPolicyChannel, forged.data(), static_cast<int>(forged.size())));
  const std::vector<uint8_t> real = signedBytes(*run.learner, kPolicyChannel, message);
  ASSERT_TRUE(bus.publishWire(kPolicyChannel, real.data(), static_cast<int>(real.size())));
  for (int i = 0; i < 5; ++i) bus.handleTimeout(10);
  EXPECT_EQ(count(bus, kPolicyChannel, WireVerdict::kUnauthenticated), 1);
  EXPECT_EQ(handled, 1) << bus.rejectSummary();
}

// ---------------------------------------------------------------------------------------------
// The actors: parameters signed by an actor's key.

constexpr int64_t kSignedRunId = 4242;

config::RunConfig smallSignedRunConfig() {
  return config::loadRunConfig(config::defaultConfigsDir(),
                               {"task=trifinger_lift", "model.policy_hidden=[16]", "model.critic_hidden=[16]",
                                "ppo.num_envs=8", "ppo.horizon=4", "ppo.minibatch_size=16", "ppo.mini_epochs=1"});
}

// Valid parameters for `rc` (the policy prefix of an initialized model).
masa::lcmt_policy_params signParamsFor(const config::RunConfig& rc, int64_t version) {
  const auto spec = sym::SymmetrySpec::load(rc.spec_path);
  model::ActorCritic<float> model(spec, rc.model);
  Rng rng(5);
  model.initialize(rng);
  masa::lcmt_policy_params p;
  p.run_id = kSignedRunId;
  p.utime = 0;
  p.version = version;
  p.method = model::methodName(rc.method);
  p.task = rc.task;
  p.num_params = model.policyParamCount();
  p.params.assign(model.params().values().data(), model.params().values().data() + p.num_params);
  p.obs_dim = spec.obsDim();
  p.obs_mean.assign(p.obs_dim, 0.1f);
  p.obs_std.assign(p.obs_dim, 2.0f);
  return p;
}

TEST(MessageSignActors, AParameterMessageSignedByAnActorsKeyIsRefusedByEveryActorAndCounted) {
  const auto rc = smallSignedRunConfig();
  SignedRun run(2, "actors");
  // Each actor on its own in-process bus, with its own key; the same bytes reach each of them.
  std::vector<std::unique_ptr<Transport>> buses;
  std::vector<std::unique_ptr<actor::Actor>> actors;
  for (int a = 0; a < 2; ++a) {
    buses.push_back(std::make_unique<Transport>("memq://", run.as(run.actors[a])));
    actor::ActorOptions o;
    o.actor_id = a;
    o.num_envs = 1;
    o.run_id = kSignedRunId;
    o.threads = 1;
    o.await_params_s = 0;
    actors.push_back(std::make_unique<actor::Actor>(rc, o, buses.back().get()));
  }
  const std::vector<uint8_t> params = encode(signParamsFor(rc, 1));
  // Actor 1's key, compromised: parameters as the learner would send them, in every field.
  const std::vector<uint8_t> forged = signedBytes(*run.actors[1], kPolicyChannel, params);
  for (int a = 0; a < 2; ++a) {
    ASSERT_TRUE(buses[a]->publishWire(kPolicyChannel, forged.data(), static_cast<int>(forged.size())));
    EXPECT_FALSE(actors[a]->pollParams(20));
    EXPECT_FALSE(actors[a]->hasParams()) << "actor " << a << " acts with parameters signed by actor 1";
    EXPECT_EQ(count(*buses[a], kPolicyChannel, WireVerdict::kNotPermitted), 1) << "actor " << a;
    EXPECT_EQ(actors[a]->paramsRejected(), 0) << "refused before decoding, not by the parameter check";
  }
  // The same parameters signed by the learner's key are taken by each.
  const std::vector<uint8_t> real = signedBytes(*run.learner, kPolicyChannel, params);
  for (int a = 0; a < 2; ++a) {
    ASSERT_TRUE(buses[a]->publishWire(kPolicyChannel, real.data(), static_cast<int>(real.size())));
    EXPECT_TRUE(actors[a]->pollParams(20)) << "actor " << a << ": " << buses[a]->rejectSummary();
    EXPECT_EQ(actors[a]->policyVersion(), 1);
  }
}

// ---------------------------------------------------------------------------------------------
// The learner: chunks signed by one actor, claiming another.

learner::LearnerOptions learnerOptions(const fs::path& dir, const SignedRun& run) {
  learner::LearnerOptions o;
  o.make_algorithm = learner::makePpoAlgorithm;
  o.url = "memq://";
  o.run_dir = dir.string();
  o.run_id = kSignedRunId;
  o.verbose = false;
  o.signed_mode = run.as(run.learner);
  return o;
}

// A whole batch (8 environments x 4 steps) of actor `actor_id`'s rollout `seq`, encoded.
std::vector<std::vector<uint8_t>> signedBatchOf(const config::RunConfig& rc, int actor_id, int64_t seq) {
  const auto spec = sym::SymmetrySpec::load(rc.spec_path);
  const int E = rc.rollout.num_envs, T = rc.rollout.horizon, od = spec.obsDim(), ad = spec.actDim();
  rollout::Rollout r;
  r.allocate(E, T, od, ad, {"keypoints", "reach", "termination"});
  r.clearEvents();
  std::mt19937_64 rng(seq + 1);
  std::normal_distribution<float> normal;
  for (float& x : r.obs) x = normal(rng);
  for (float& x : r.reward) x = normal(rng);
  for (float& x : r.mean) x = 0.0f;
  for (float& x : r.env_log_std) x = 0.0f;
  for (float& x : r.actions) x = normal(rng);
  for (float& x : r.log_prob) x = -1.0f;
  actor::RolloutChunker chunker(2000);  // several chunks
  std::vector<std::vector<uint8_t>> out;
  for (const auto& c : chunker.split(r, {kSignedRunId, actor_id, seq, 0})) out.push_back(encode(c));
  return out;
}

bool stepUntilSignedUpdate(learner::Learner& l, int max_steps = 100) {
  bool updated = false;
  for (int i = 0; i < max_steps && !updated; ++i) updated = l.step(0);
  return updated;
}

TEST(MessageSignLearner, ARolloutChunkSignedByActorOneClaimingActorZeroIsRefusedAndCounted) {
  const auto rc = smallSignedRunConfig();
  SignedRun run(2, "claims");
  const fs::path dir = run.dir / "learner";
  learner::Learner learner(rc, learnerOptions(dir, run));
  auto& bus = dynamic_cast<Transport&>(learner.transport());  // bytes on the wire, as a forger sends them
  const auto chunks = signedBatchOf(rc, 0, 0);
  ASSERT_GT(chunks.size(), 1u);
  // Actor 1's key on a whole batch that names actor 0.
  for (const auto& c : chunks) {
    const auto b = signedBytes(*run.actors[1], kRolloutChannel, c);
    ASSERT_TRUE(bus.publishWire(kRolloutChannel, b.data(), static_cast<int>(b.size())));
  }
  EXPECT_FALSE(stepUntilSignedUpdate(learner, 30));
  EXPECT_EQ(learner.version(), 0);
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kClaimsAnotherActor], static_cast<int64_t>(chunks.size()));
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kAccepted], 0);
  // The same chunks signed by actor 0 are taken: the refused copies left no trace (no duplicate).
  for (const auto& c : chunks) {
    const auto b = signedBytes(*run.actors[0], kRolloutChannel, c);
    ASSERT_TRUE(bus.publishWire(kRolloutChannel, b.data(), static_cast<int>(b.size())));
  }
  ASSERT_TRUE(stepUntilSignedUpdate(learner)) << bus.rejectSummary();
  EXPECT_EQ(learner.version(), 1);
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kDuplicate], 0);
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kAccepted], static_cast<int64_t>(chunks.size()));
}

TEST(MessageSignLearner, AReplayedChunkIsRefusedAsReplayedAndANonActorsChunkIsNotPermitted) {
  const auto rc = smallSignedRunConfig();
  SignedRun run(1, "learner_replay");
  learner::Learner learner(rc, learnerOptions(run.dir / "learner", run));
  auto& bus = dynamic_cast<Transport&>(learner.transport());  // bytes on the wire, as a forger sends them
  const auto chunks = signedBatchOf(rc, 0, 0);
  std::vector<std::vector<uint8_t>> sent;
  for (const auto& c : chunks) sent.push_back(signedBytes(*run.actors[0], kRolloutChannel, c));
  for (const auto& b : sent) bus.publishWire(kRolloutChannel, b.data(), static_cast<int>(b.size()));
  ASSERT_TRUE(stepUntilSignedUpdate(learner)) << bus.rejectSummary();
  for (const auto& b : sent) bus.publishWire(kRolloutChannel, b.data(), static_cast<int>(b.size()));
  // The learner's own key on a chunk: the roster lets it publish parameters, not rollouts.
  const auto by_learner = signedBytes(*run.learner, kRolloutChannel, chunks[0]);
  bus.publishWire(kRolloutChannel, by_learner.data(), static_cast<int>(by_learner.size()));
  for (int i = 0; i < 10; ++i) learner.step(0);
  // Counters are the signer's clock (issue #55, item 3): a replay more than the window (1024 us)
  // older than the newest chunk is refused as beyond_window instead (a loaded machine signs 8 chunks
  // in more than 1 ms).
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kReplayed] + learner.dropStats()[learner::DropReason::kBeyondWindow],
            static_cast<int64_t>(sent.size()));
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kNotPermitted], 1);
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kDuplicate], 0) << "replays never reach the assembler";
  EXPECT_EQ(learner.dropStats()[learner::DropReason::kAccepted], static_cast<int64_t>(sent.size()));
}

}  // namespace
}  // namespace masa::transport
