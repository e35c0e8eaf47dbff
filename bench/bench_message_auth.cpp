// What message authentication (common/transport/message_auth.hpp) costs per message: the HMAC-SHA256
// trailer a publisher appends (Seal) and a receiver checks (Open), on the messages a run sends most
// and biggest:
//   Chunk:  one full rollout chunk (RolloutChunker's 60 KB budget, a1_beam's dimensions), what every
//           actor sends about (num_envs x horizon x obs_dim x 4 / 60 KB) times per rollout;
//   Policy/<recipe>: the parameter broadcast of a shipped recipe's model (the policy prefix, as the
//           learner sends it), once per update and on every periodic repeat;
//   Bytes/N: plain buffers, for the cost's slope in the size.
// bytes_per_second is SHA-256's throughput here; time per message is the cost.
// Sign*/Verify* do the same for a signed run's SIG1 trailer (common/transport/message_sign.hpp):
// Ed25519 by the sender's own key over a SHA-256 of the message, counter and sender; Verify* is
// the receiver's whole check (roster, permission, signature; not the counter window, which is a
// few bit operations).
//   build/bench/bench_message_auth --benchmark_min_time=0.5
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <unistd.h>
#include <cstdint>
#include <string>
#include <vector>

#include "common/config/run_config.hpp"
#include "common/model/actor_critic.hpp"
#include "common/model/method.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "common/rollout/rollout.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/message_auth.hpp"
#include "common/transport/message_sign.hpp"
#include "actors/rollout_chunker.hpp"
#include "masa/lcmt_policy_params.hpp"

namespace {

using namespace masa;

template <class Msg>
std::vector<uint8_t> encoded(const Msg& m) {
  std::vector<uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()) + transport::kAuthTrailerBytes);
  m.encode(bytes.data(), 0, m.getEncodedSize());
  bytes.resize(static_cast<std::size_t>(m.getEncodedSize()));
  return bytes;
}

// The first chunk of an a1_beam rollout of 32 environments x 32 steps: a full 60 KB one.
std::vector<uint8_t> rolloutChunk() {
  rollout::Rollout r;
  r.allocate(32, 32, 47, 12, {"velocity", "alive"});
  r.clearEvents();
  for (std::size_t i = 0; i < r.obs.size(); ++i) r.obs[i] = std::sin(static_cast<float>(i));
  actor::RolloutChunker chunker;
  const auto chunks = chunker.split(r, {1, 0, 0, 0});
  return encoded(chunks[0]);
}

// The learner's broadcast for a recipe: its model's policy parameters, and the normalizer.
std::vector<uint8_t> policyMessage(const std::string& recipe) {
  const config::RunConfig rc = config::loadRunConfig(config::defaultConfigsDir(), {"@" + recipe});
  model::ActorCritic<float> model(sym::SymmetrySpec::load(rc.spec_path), rc.model);
  masa::lcmt_policy_params m;
  m.method = model::methodName(rc.method);
  m.task = rc.task;
  m.num_params = model.policyParamCount();
  m.params.assign(static_cast<std::size_t>(m.num_params), 0.5f);
  m.obs_dim = model.obsDim();
  m.obs_mean.assign(static_cast<std::size_t>(m.obs_dim), 0.0f);
  m.obs_std.assign(static_cast<std::size_t>(m.obs_dim), 1.0f);
  return encoded(m);
}

void sealEach(benchmark::State& state, const std::vector<uint8_t>& message, const char* channel) {
  const transport::MessageAuthenticator auth(transport::RunKey::random());
  uint8_t trailer[transport::kAuthTrailerBytes];
  for (auto _ : state) {
    auth.seal(channel, message.data(), static_cast<int>(message.size()), trailer);
    benchmark::DoNotOptimize(trailer);
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(message.size()));
  state.counters["message_bytes"] = static_cast<double>(message.size());
}

void openEach(benchmark::State& state, const std::vector<uint8_t>& message, const char* channel) {
  const transport::MessageAuthenticator auth(transport::RunKey::random());
  std::vector<uint8_t> sealed(message);
  sealed.resize(message.size() + transport::kAuthTrailerBytes);
  auth.seal(channel, message.data(), static_cast<int>(message.size()), sealed.data() + message.size());
  for (auto _ : state) {
    const int size = auth.open(channel, sealed.data(), static_cast<int>(sealed.size()));
    if (size != static_cast<int>(message.size())) state.SkipWithError("a sealed message did not open");
    benchmark::DoNotOptimize(size);
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(message.size()));
  state.counters["message_bytes"] = static_cast<double>(message.size());
}

void BM_SealChunk(benchmark::State& state) { sealEach(state, rolloutChunk(), transport::kRolloutChannel); }
void BM_OpenChunk(benchmark::State& state) { openEach(state, rolloutChunk(), transport::kRolloutChannel); }
BENCHMARK(BM_SealChunk)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_OpenChunk)->Unit(benchmark::kMicrosecond);

void BM_SealPolicy(benchmark::State& state, const std::string& recipe) {
  sealEach(state, policyMessage(recipe), transport::kPolicyChannel);
}
void BM_OpenPolicy(benchmark::State& state, const std::string& recipe) {
  openEach(state, policyMessage(recipe), transport::kPolicyChannel);
}
BENCHMARK_CAPTURE(BM_SealPolicy, a1_beam, std::string("a1_beam"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_OpenPolicy, a1_beam, std::string("a1_beam"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SealPolicy, humanoid_tightrope, std::string("humanoid_tightrope"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_OpenPolicy, humanoid_tightrope, std::string("humanoid_tightrope"))->Unit(benchmark::kMicrosecond);

// A learner's and an actor's key in a temporary directory, and their roster.
struct Keys {
  std::filesystem::path dir = std::filesystem::temp_directory_path() / ("masa_bench_sign_" + std::to_string(::getpid()));
  std::shared_ptr<transport::Roster> roster = std::make_shared<transport::Roster>();
  std::shared_ptr<transport::MessageSigner> learner, actor;
  Keys() {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const transport::SenderId l{transport::Role::kLearner, 0}, a{transport::Role::kActor, 0};
    roster->add(l, integrity::generateKeyPair((dir / "l.key").string(), (dir / "l.pub").string()), transport::defaultChannels(l.role));
    roster->add(a, integrity::generateKeyPair((dir / "a.key").string(), (dir / "a.pub").string()), transport::defaultChannels(a.role));
    learner = transport::MessageSigner::load((dir / "l.key").string(), l, *roster);
    actor = transport::MessageSigner::load((dir / "a.key").string(), a, *roster);
    std::filesystem::remove_all(dir);
  }
};

void signEach(benchmark::State& state, const std::vector<uint8_t>& message, const char* channel, bool as_learner) {
  Keys keys;
  transport::MessageSigner& signer = as_learner ? *keys.learner : *keys.actor;
  uint8_t trailer[transport::kSigTrailerBytes];
  for (auto _ : state) {
    signer.seal(channel, message.data(), static_cast<int>(message.size()), trailer);
    benchmark::DoNotOptimize(trailer);
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(message.size()));
  state.counters["message_bytes"] = static_cast<double>(message.size());
}

void verifyEach(benchmark::State& state, const std::vector<uint8_t>& message, const char* channel, bool as_learner) {
  Keys keys;
  const transport::MessageVerifier verifier(keys.roster, 0);
  std::vector<uint8_t> signed_bytes(message);
  signed_bytes.resize(message.size() + transport::kSigTrailerBytes);
  (as_learner ? *keys.learner : *keys.actor)
      .seal(channel, message.data(), static_cast<int>(message.size()), signed_bytes.data() + message.size());
  for (auto _ : state) {
    const transport::OpenedMessage m = verifier.open(channel, signed_bytes.data(), static_cast<int>(signed_bytes.size()));
    if (m.verdict != transport::WireVerdict::kOk) state.SkipWithError("a signed message did not verify");
    benchmark::DoNotOptimize(m);
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(message.size()));
  state.counters["message_bytes"] = static_cast<double>(message.size());
}

void BM_SignChunk(benchmark::State& state) { signEach(state, rolloutChunk(), transport::kRolloutChannel, false); }
void BM_VerifyChunk(benchmark::State& state) { verifyEach(state, rolloutChunk(), transport::kRolloutChannel, false); }
BENCHMARK(BM_SignChunk)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_VerifyChunk)->Unit(benchmark::kMicrosecond);
void BM_SignPolicy(benchmark::State& state, const std::string& recipe) {
  signEach(state, policyMessage(recipe), transport::kPolicyChannel, true);
}
void BM_VerifyPolicy(benchmark::State& state, const std::string& recipe) {
  verifyEach(state, policyMessage(recipe), transport::kPolicyChannel, true);
}
BENCHMARK_CAPTURE(BM_SignPolicy, a1_beam, std::string("a1_beam"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_VerifyPolicy, a1_beam, std::string("a1_beam"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SignPolicy, humanoid_tightrope, std::string("humanoid_tightrope"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_VerifyPolicy, humanoid_tightrope, std::string("humanoid_tightrope"))->Unit(benchmark::kMicrosecond);
void BM_VerifyBytes(benchmark::State& state) {
  verifyEach(state, std::vector<uint8_t>(static_cast<std::size_t>(state.range(0)), 0x5a), transport::kHeartbeatChannel, false);
}
BENCHMARK(BM_VerifyBytes)->Arg(200)->Unit(benchmark::kMicrosecond);

void BM_SealBytes(benchmark::State& state) {
  sealEach(state, std::vector<uint8_t>(static_cast<std::size_t>(state.range(0)), 0x5a), transport::kHeartbeatChannel);
}
BENCHMARK(BM_SealBytes)->RangeMultiplier(8)->Range(64, 1 << 21)->Unit(benchmark::kMicrosecond);

}  // namespace
