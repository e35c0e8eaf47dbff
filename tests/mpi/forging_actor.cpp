// A compromised actor inside a signed MPI job (issue #33, item 2), for tests/mpi/signed_job.sh:
//   mpirun -np 2 masa_learner ... : -np 2 masa_actor ... : -np 1 masa_test_forging_actor
// It joins the job as an actor (its key made in memory and listed in the job's roster, as a real
// actor's), and with that key it
//   - re-signs every parameter message of the learner it hears, its version raised by 1000 and its
//     parameters zeroed, on MASA_POLICY: every actor must refuse it (not_permitted);
//   - sends the same forgery unsigned, as anyone on the LAN can: refused (unauthenticated);
//   - sends heartbeats in actor 0's name: learner rank 0 must refuse them (claims_another_sender);
//   - copies every chunk actor 1 signs for learner rank 1 (on rank 1's rollout URL) to rank 0's
//     rollout URL, byte for byte: rank 0 must refuse them (another_ranks_actor; issue #55, item 3).
// It stays until the learner ranks end training, then prints what it sent and exits 0.
#include <chrono>
#include <cstdio>
#include <exception>
#include <vector>

#include "common/cluster/job_plan.hpp"
#include "common/cluster/mpi_job.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/job_roster.hpp"
#include "common/transport/lcm_url.hpp"
#include "common/transport/message_sign.hpp"
#include "common/transport/transport.hpp"
#include "masa/lcmt_actor_heartbeat.hpp"
#include "masa/lcmt_policy_params.hpp"

int main() {
  using namespace masa;
  cluster::MpiJob job(cluster::Role::kActor);
  try {
    // The same collectives in the same order as masa_actor.
    auto keys = transport::jobSignedMode({transport::Role::kActor, static_cast<uint32_t>(job.roleIndex())},
                                         [&](const std::vector<uint8_t>& mine) { return job.gatherFromEveryProcess(mine); });
    std::vector<uint8_t> bytes;
    job.shareFromLearnerZero(bytes);
    const auto plan = cluster::JobPlan::decode(bytes);
    if (!plan.signed_job) throw std::runtime_error("the job is not signed: nothing to test");
    transport::Transport lcm(plan.url, keys);
    int64_t signed_forgeries = 0, unsigned_forgeries = 0, heartbeats = 0, heard = 0, copied = 0;
    // Rank 1's rollouts as they are on the wire (not verified), and rank 0's rollout URL to copy them to.
    const int ranks = job.learnerCount();
    transport::Transport rank1_in(transport::rankRolloutUrl(plan.url, 1 % ranks, ranks));
    transport::Transport rank0_out(transport::rankRolloutUrl(plan.url, 0, ranks));
    rank1_in.subscribeRaw(transport::kRolloutChannel, [&](const void* data, int size) {
      transport::SenderId sender;
      uint64_t counter = 0;
      if (!transport::peekSigner(data, size, sender, counter) || sender != transport::SenderId{transport::Role::kActor, 1})
        return;
      if (rank0_out.publishWire(transport::kRolloutChannel, data, size)) ++copied;
    });
    lcm.subscribe<lcmt_policy_params>(transport::kPolicyChannel, [&](const lcmt_policy_params& real) {
      ++heard;
      lcmt_policy_params forged = real;
      forged.version += 1000;
      for (float& p : forged.params) p = 0.0f;
      std::vector<uint8_t> enc(static_cast<std::size_t>(forged.getEncodedSize()));
      forged.encode(enc.data(), 0, static_cast<int>(enc.size()));
      if (lcm.publishRaw(transport::kPolicyChannel, enc.data(), static_cast<int>(enc.size()))) ++signed_forgeries;
      if (lcm.publishWire(transport::kPolicyChannel, enc.data(), static_cast<int>(enc.size()))) ++unsigned_forgeries;
    });
    auto next_heartbeat = std::chrono::steady_clock::now();
    while (!job.trainingFinished()) {
      lcm.handleTimeout(50);
      rank1_in.drain();
      if (std::chrono::steady_clock::now() < next_heartbeat) continue;
      next_heartbeat += std::chrono::milliseconds(200);
      lcmt_actor_heartbeat hb{};
      hb.run_id = plan.run_id;
      hb.actor_id = 0;  // not this actor
      hb.utime = transport::wallClockMicros();
      hb.hostname = "forger";
      hb.num_envs = 1;
      hb.params_version = 1000000;
      if (lcm.publish(transport::kHeartbeatChannel, hb)) ++heartbeats;
    }
    std::printf("forging actor %d: heard %lld parameter messages; sent %lld re-signed with an actor key, %lld unsigned, "
                "%lld heartbeats in actor 0's name, %lld of actor 1's chunks copied to rank 0\n",
                job.roleIndex(), static_cast<long long>(heard), static_cast<long long>(signed_forgeries),
                static_cast<long long>(unsigned_forgeries), static_cast<long long>(heartbeats), static_cast<long long>(copied));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "forging actor: %s\n", e.what());
    job.abort(2);
  }
  return 0;
}
