// Each data-parallel learner rank's rollout URL (docs/scaling.md): learner and actors derive it
// from the job's URL with one function.
#include <gtest/gtest.h>

#include <stdexcept>

#include "common/transport/lcm_url.hpp"

namespace masa::transport {
namespace {

TEST(RankRolloutUrl, OneRankKeepsTheJobsUrlAndRanksTakeThePortsAfterIt) {
  const std::string url = "udpm://239.255.76.67:7667?ttl=1&recv_buf_size=8388608";
  EXPECT_EQ(rankRolloutUrl(url, 0, 1), url);  // one learner hears its actors where it publishes
  EXPECT_EQ(rankRolloutUrl(url, 0, 2), "udpm://239.255.76.67:7668?ttl=1&recv_buf_size=8388608");
  EXPECT_EQ(rankRolloutUrl(url, 1, 2), "udpm://239.255.76.67:7669?ttl=1&recv_buf_size=8388608");
  EXPECT_EQ(rankRolloutUrl("udpm://239.255.76.67:7667", 3, 4), "udpm://239.255.76.67:7671");
  EXPECT_EQ(rankRolloutUrl("memq://", 0, 1), "memq://");
}

TEST(RankRolloutUrl, RefusesWhatCannotGiveEachRankItsOwnChannel) {
  EXPECT_THROW(rankRolloutUrl("tcpq://hub:7700", 0, 2), std::invalid_argument);  // a hub relays to everyone
  EXPECT_THROW(rankRolloutUrl("udpm://239.255.76.67?ttl=0", 0, 2), std::invalid_argument);  // no port
  EXPECT_THROW(rankRolloutUrl("udpm://239.255.76.67:76x7", 0, 2), std::invalid_argument);
  EXPECT_THROW(rankRolloutUrl("udpm://239.255.76.67:65535", 0, 2), std::invalid_argument);  // past the last port
  EXPECT_THROW(rankRolloutUrl("udpm://239.255.76.67:7667", 2, 2), std::invalid_argument);  // no rank 2 of 2
}

}  // namespace
}  // namespace masa::transport
