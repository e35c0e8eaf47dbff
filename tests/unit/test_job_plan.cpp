// JobPlan::decode on damaged plans (docs/inputs.md gap 11): the plan crosses the MPI interconnect
// unauthenticated (the interconnect is trusted, docs/scaling.md), so decode's part is to be exact:
// every truncation and trailing byte refused, nothing read past the end, and whatever it accepts is
// what the bytes say (re-encoding gives the same bytes).
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/cluster/job_plan.hpp"
#include "file_mutations.hpp"

namespace {

using masa::cluster::JobPlan;

// with_key: the run key (HMAC); signed_job: a signed job; neither: --no-auth.
JobPlan samplePlan(bool with_key, bool signed_job = false) {
  JobPlan plan;
  plan.signed_job = signed_job;
  plan.run_id = 0x1234567890abcdefLL;
  plan.url = "udpm://239.255.76.67:7667?ttl=1&recv_buf_size=4194304";
  if (with_key) {
    plan.key.emplace();
    for (size_t i = 0; i < plan.key->size(); ++i) (*plan.key)[i] = static_cast<uint8_t>(7 * i + 1);
  }
  return plan;
}

TEST(JobPlan, RoundTripsWithAKeySignedAndWithoutAuthentication) {
  for (auto [with_key, signed_job] : {std::pair{true, false}, std::pair{false, true}, std::pair{false, false}}) {
    const JobPlan plan = samplePlan(with_key, signed_job);
    const JobPlan back = JobPlan::decode(plan.encode());
    EXPECT_EQ(back.run_id, plan.run_id);
    EXPECT_EQ(back.url, plan.url);
    EXPECT_EQ(back.key, plan.key);
    EXPECT_EQ(back.signed_job, signed_job);
  }
  // A plan cannot say both: an actor would not know which to use.
  EXPECT_THROW(samplePlan(true, true).encode(), std::logic_error);
}

TEST(JobPlan, AnUnknownAuthenticationByteIsRefusedByName) {
  std::vector<uint8_t> bytes = samplePlan(false, true).encode();
  bytes.back() = 3;  // the last byte of a plan without a key: how it is authenticated
  try {
    JobPlan::decode(bytes);
    FAIL() << "authentication byte 3 accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad authentication byte 3"), std::string::npos) << e.what();
  }
}

TEST(JobPlan, EveryTruncationAndAnyTrailingByteIsRefused) {
  const std::vector<uint8_t> bytes = samplePlan(true).encode();
  for (size_t n = 0; n < bytes.size(); ++n)
    EXPECT_THROW(JobPlan::decode(std::vector<uint8_t>(bytes.begin(), bytes.begin() + n)), std::runtime_error)
        << "cut to " << n << " of " << bytes.size() << " bytes";
  std::vector<uint8_t> longer = bytes;
  longer.push_back(0);
  EXPECT_THROW(JobPlan::decode(longer), std::runtime_error);
}

TEST(JobPlan, DamagedPlansAreRefusedOrReadExactlyAsTheirBytesSay) {
  std::mt19937_64 rng(11);
  int refused = 0, accepted = 0;
  for (auto [with_key, signed_job] : {std::pair{true, false}, std::pair{false, true}, std::pair{false, false}}) {
    const std::vector<uint8_t> clean = samplePlan(with_key, signed_job).encode();
    const std::string original(clean.begin(), clean.end());
    for (int i = 0; i < 2000; ++i) {
      const masa::fuzz::FileMutation m = masa::fuzz::mutateFile(original, rng);
      const std::vector<uint8_t> damaged(m.bytes.begin(), m.bytes.end());
      try {
        const JobPlan plan = JobPlan::decode(damaged);
        ++accepted;
        EXPECT_EQ(plan.encode(), damaged) << m.what << ": accepted, but not what its bytes say";
        EXPECT_LE(plan.url.size(), 4096u) << m.what;
      } catch (const std::runtime_error& e) {
        ++refused;
        EXPECT_NE(std::string(e.what()).find("job plan from learner rank 0"), std::string::npos) << e.what();
      }
    }
  }
  // Most damage changes the length or the magic; a flipped bit in the URL or key is a valid plan.
  EXPECT_GT(refused, 3000);
  EXPECT_GT(accepted, 0);
}

}  // namespace
