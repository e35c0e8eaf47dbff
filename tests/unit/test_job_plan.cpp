// JobPlan::decode on damaged plans (docs/inputs.md gap 11): the plan crosses the MPI interconnect
// unauthenticated (the interconnect is trusted, docs/scaling.md), so decode's part is to be exact:
// every truncation and trailing byte refused, nothing read past the end, and whatever it accepts is
// what the bytes say (re-encoding gives the same bytes).
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/cluster/job_plan.hpp"
#include "file_mutations.hpp"

namespace {

using masa::cluster::JobPlan;

JobPlan samplePlan(bool with_key) {
  JobPlan plan;
  plan.run_id = 0x1234567890abcdefLL;
  plan.url = "udpm://239.255.76.67:7667?ttl=1&recv_buf_size=4194304";
  if (with_key) {
    plan.key.emplace();
    for (size_t i = 0; i < plan.key->size(); ++i) (*plan.key)[i] = static_cast<uint8_t>(7 * i + 1);
  }
  return plan;
}

TEST(JobPlan, RoundTripsWithAndWithoutAKey) {
  for (bool with_key : {true, false}) {
    const JobPlan plan = samplePlan(with_key);
    const JobPlan back = JobPlan::decode(plan.encode());
    EXPECT_EQ(back.run_id, plan.run_id);
    EXPECT_EQ(back.url, plan.url);
    EXPECT_EQ(back.key, plan.key);
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
  for (bool with_key : {true, false}) {
    const std::vector<uint8_t> clean = samplePlan(with_key).encode();
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
  EXPECT_GT(refused, 2000);
  EXPECT_GT(accepted, 0);
}

}  // namespace
