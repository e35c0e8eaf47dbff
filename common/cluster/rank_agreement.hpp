// Data-parallel ranks must hold the same parameters: they start from rank 0's and apply the same
// reduced steps, so any difference is a bug or a fault (a flipped bit, a rank resumed from another
// checkpoint). Each rank hashes its state, the hashes are gathered, and every rank throws the same
// error naming the ranks that differ from rank 0, so the whole job stops instead of training on
// with ranks that disagree.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "common/cluster/communicator.hpp"

namespace masa::cluster {

class RankDisagreement : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// FNV-1a over the bytes (fast, and enough to tell states apart: this guards against faults, not
// against an adversary).
uint64_t hashBytes(const void* data, std::size_t bytes, uint64_t seed = 0xcbf29ce484222325ULL);

// Collective: throws RankDisagreement on every rank when any rank's hash differs from rank 0's.
void requireSameOnEveryRank(Communicator& comm, uint64_t hash, const std::string& what);

}  // namespace masa::cluster
