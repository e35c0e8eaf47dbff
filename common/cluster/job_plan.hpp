// What learner rank 0 tells every process of an MPI job once the run exists (MpiJob::
// shareFromLearnerZero): the run id the actors must carry, the URL the parameters go out on (each
// rank's rollout URL follows from it), and how messages are authenticated: signed (every process
// with its own key, made in memory; the roster gathered over MPI, common/transport/job_roster.hpp),
// the run key (which so never touches a command line or a shared file), or not at all. Encoded as
// bytes for the broadcast; decode() refuses anything malformed.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace masa::cluster {

struct JobPlan {
  int64_t run_id = 0;
  std::string url;
  std::optional<std::array<uint8_t, 32>> key;  // the run key (HMAC mode)
  bool signed_job = false;                      // signed with the job's roster (then no key)
  // Neither: --no-auth.

  std::vector<uint8_t> encode() const;
  static JobPlan decode(const std::vector<uint8_t>& bytes);  // throws std::runtime_error
};

}  // namespace masa::cluster
