// The `offline` section is read by the strict config reader (common/config/config_section.hpp):
// every number finite, errors naming offline.<key> and where it was set.
#include <gtest/gtest.h>

#include <string>

#include "common/core/config_error.hpp"
#include "config_error_support.hpp"
#include "learner/offline/offline_config.hpp"

namespace masa::offline {
namespace {

OfflineConfig readWith(const std::vector<std::string>& sets) {
  std::vector<std::string> overrides{"task=a1_beam"};
  overrides.insert(overrides.end(), sets.begin(), sets.end());
  return readOfflineConfig(config::loadRunConfig(std::string(MASA_SOURCE_DIR) + "/configs", overrides));
}

// Before the shared reader, positive() took infinity and the log-std bounds took -.inf.
TEST(OfflineConfigTest, InfinityOrNaNIsRefusedNamingTheKeyPath) {
  for (const std::string set : {"offline.beta=.inf", "offline.learning_rate=.inf", "offline.max_weight=.nan",
                                "offline.log_std_min=-.inf", "offline.log_std_max=.inf"}) {
    const ConfigError e = test::configErrorOf([&] { readWith({set}); });
    EXPECT_EQ(e.key(), set.substr(0, set.find('='))) << set << ": " << e.what();
    EXPECT_EQ(e.file(), "command line") << e.what();
  }
}

}  // namespace
}  // namespace masa::offline
