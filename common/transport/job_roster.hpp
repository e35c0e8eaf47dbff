// The roster of a signed MPI job (docs/reliability.md, "Signed MPI jobs"): no key file exists.
// Every process of the job makes its own Ed25519 key in memory at start and says (role, index,
// public key) to every other over MPI (an all-gather, the interconnect the launcher trusts);
// every process then builds the same roster from what was gathered:
//   learner 0   MASA_POLICY, MASA_LEARNER_STATS   (rank 0 speaks for the ranks)
//   actor i     MASA_ROLLOUT, MASA_ACTOR_HEARTBEAT
// Learner ranks above 0 publish nothing over LCM: they are not listed, and their transport only
// verifies. So a private key never leaves its process, and no secret is on a command line or disk.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "common/transport/roster.hpp"
#include "common/transport/transport.hpp"

namespace masa::transport {

// One process's record in the gather: role (1 byte), index (4 bytes BE), public key (32 bytes).
inline constexpr int kJobKeyRecordBytes = 1 + 4 + 32;
std::vector<uint8_t> jobKeyRecord(SenderId id, const integrity::PublicKeyBytes& key);

// The roster of the job from every process's record, concatenated (MpiJob::gatherFromEveryProcess).
// Throws std::runtime_error naming the job and the record when one is malformed (a size that is
// not a multiple of records, a byte that is no role) or a sender comes twice.
Roster jobRoster(const std::vector<uint8_t>& records);

// Collective over the job: makes this process's key, gathers every process's record with
// `gather_all` (this process's record in, every process's out) and returns this process's
// signing identity: its signer (none for a learner rank above 0: it only verifies) and the roster.
using GatherAll = std::function<std::vector<uint8_t>(const std::vector<uint8_t>&)>;
SignedMode jobSignedMode(SenderId me, const GatherAll& gather_all);

}  // namespace masa::transport
