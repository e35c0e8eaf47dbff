#include "common/cluster/rank_agreement.hpp"

#include <sstream>
#include <vector>

namespace masa::cluster {

uint64_t hashBytes(const void* data, std::size_t bytes, uint64_t seed) {
  const auto* p = static_cast<const unsigned char*>(data);
  uint64_t h = seed;
  for (std::size_t i = 0; i < bytes; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

void requireSameOnEveryRank(Communicator& comm, uint64_t hash, const std::string& what) {
  if (comm.size() == 1) return;
  const std::vector<int64_t> all = comm.gather(static_cast<int64_t>(hash));
  std::ostringstream differ;
  int n = 0;
  for (std::size_t r = 1; r < all.size(); ++r)
    if (all[r] != all[0]) differ << (n++ ? ", " : "") << r;
  if (n == 0) return;
  throw RankDisagreement(what + " differ between learner ranks: rank" + (n > 1 ? "s " : " ") + differ.str() +
                         " disagree" + (n > 1 ? "" : "s") + " with rank 0 (of " + std::to_string(all.size()) +
                         "); stopping the run");
}

}  // namespace masa::cluster
