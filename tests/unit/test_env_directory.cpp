// MASA_CONFIGS and MASA_ROOT name directories: set to anything else they are refused where they are
// read, naming the variable and its value (docs/inputs.md gap 17), not as a missing file later.
#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <optional>
#include <string>

#include "common/config/run_config.hpp"
#include "common/core/config_error.hpp"
#include "tests/unit/task_test_support.hpp"

namespace masa {
namespace {

// Sets a variable for one test and puts back what was there.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) setenv(name, value, 1); else unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_) setenv(name_, old_->c_str(), 1); else unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

void expectRefusedNaming(const char* variable, const std::string& value, const std::function<void()>& read) {
  try {
    read();
    ADD_FAILURE() << variable << "='" << value << "' was taken";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), variable) << e.what();
    EXPECT_NE(std::string(e.what()).find("'" + value + "' is not a directory"), std::string::npos) << e.what();
  }
}

TEST(EnvironmentDirectories, MasaConfigsThatNamesNoDirectoryIsRefusedNamingIt) {
  const std::string file = std::string(MASA_SOURCE_DIR) + "/CMakeLists.txt";
  for (const std::string& bad : {std::string("/no/such/configs"), file, std::string()}) {
    ScopedEnv env("MASA_CONFIGS", bad.c_str());
    expectRefusedNaming("MASA_CONFIGS", bad, [] { config::defaultConfigsDir(); });
  }
  {
    ScopedEnv env("MASA_CONFIGS", MASA_SOURCE_DIR "/configs");
    EXPECT_EQ(config::defaultConfigsDir(), MASA_SOURCE_DIR "/configs");
  }
  ScopedEnv unset("MASA_CONFIGS", nullptr);
  EXPECT_EQ(config::defaultConfigsDir(), std::string(MASA_SOURCE_DIR) + "/configs");
}

TEST(EnvironmentDirectories, MasaRootThatNamesNoDirectoryIsRefusedWhenATaskFindsItsModel) {
  {
    ScopedEnv env("MASA_ROOT", "/no/such/root");
    expectRefusedNaming("MASA_ROOT", "/no/such/root", [] { test::runConfigFactory("a1_beam"); });
  }
  ScopedEnv env("MASA_ROOT", MASA_SOURCE_DIR);
  EXPECT_NO_THROW(test::runConfigFactory("a1_beam"));
}

}  // namespace
}  // namespace masa
