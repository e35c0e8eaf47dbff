// The `offline` section is read by the strict config reader (common/core/config_section.hpp):
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

// Each range by its edge (docs/inputs.md gap 15): the value just outside is refused by key, the
// edge itself where the range is closed is taken.
TEST(OfflineConfigTest, EachRangeRefusesTheValueJustOutsideByKey) {
  const struct {
    const char* refused;
    const char* taken;
  } cases[] = {{"offline.expectile=0", "offline.expectile=0.01"},  {"offline.expectile=1", "offline.expectile=0.99"},
               {"offline.discount=1.01", "offline.discount=1"},    {"offline.discount=-0.01", "offline.discount=0"},
               {"offline.polyak=0", "offline.polyak=1"},           {"offline.beta=0", "offline.beta=0.1"},
               {"offline.steps=0", "offline.steps=1"},             {"offline.batch_size=0", "offline.batch_size=1"},
               {"offline.log_every=0", "offline.log_every=1"},     {"offline.eval_every=-1", "offline.eval_every=0"},
               {"offline.q_hidden=[]", "offline.q_hidden=[4]"},    {"offline.algo=cql", "offline.algo=bc"},
               {"offline.log_std_min=2", "offline.log_std_min=1.9"}};
  for (const auto& c : cases) {
    const std::string refused = c.refused;
    const ConfigError e = test::configErrorOf([&] { readWith({refused}); });
    EXPECT_EQ(e.key(), refused.substr(0, refused.find('='))) << refused << ": " << e.what();
    EXPECT_NO_THROW(readWith({c.taken})) << c.taken;
  }
}

}  // namespace
}  // namespace masa::offline
