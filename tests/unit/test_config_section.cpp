// The one strict config reader (common/config/config_layers.hpp, config_section.hpp): the schema's
// keys only, the file or "command line" and the key path in every error, finite numbers, ranges.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <string>

#include "common/config/config_layers.hpp"
#include "common/config/nearest_name.hpp"
#include "common/core/config_error.hpp"
#include "common/core/config_section.hpp"
#include "common/sim/env_params.hpp"
#include "config_error_support.hpp"

namespace masa::config {
namespace {

const char* kSchema = R"(
name: walker
net:
  lr: 3.0e-4
  gamma: 0.99
  steps: 100
  widths: [64, 64]
  pose: [0.5, -0.5]
  mode: fast
  on: true
env: {}
)";

ConfigLayers layers() { return ConfigLayers(YAML::Load(kSchema), "defaults.yaml", {{"env"}, {{"net.rate", "lr"}}}); }

std::string text(const ConfigError& e) { return e.what(); }

TEST(ConfigLayers, UnknownKeyNamesTheFileTheKeyPathAndTheKnownKeys) {
  ConfigLayers l = layers();
  const ConfigError e = test::configErrorOf([&] { l.overlay(YAML::Load("net: {gamma: 0.9, stpes: 3}"), "robot.yaml"); });
  EXPECT_EQ(e.file(), "robot.yaml");
  EXPECT_EQ(e.key(), "net.stpes");
  EXPECT_NE(text(e).find("unknown key (known here: lr, gamma, steps, widths, pose, mode, on)"), std::string::npos)
      << text(e);
  EXPECT_NE(text(e).find("did you mean 'steps'?"), std::string::npos) << text(e);
  // Far from every known key: no guess.
  const ConfigError far = test::configErrorOf([&] { l.overlay(YAML::Load("colour: red"), "robot.yaml"); });
  EXPECT_EQ(far.key(), "colour");
  EXPECT_EQ(text(far).find("did you mean"), std::string::npos) << text(far);
}

TEST(ConfigLayers, ACommandLineSettingGetsTheFileChecks) {
  ConfigLayers l = layers();
  const ConfigError unknown = test::configErrorOf([&] { l.set("net.gama", YAML::Load("0.9")); });
  EXPECT_EQ(unknown.file(), "command line");
  EXPECT_EQ(unknown.key(), "net.gama");
  EXPECT_NE(text(unknown).find("did you mean 'gamma'?"), std::string::npos) << text(unknown);
  EXPECT_EQ(test::configErrorOf([&] { l.set("net.lr", YAML::Load("{a: 1}")); }).key(), "net.lr");       // a map for a value
  EXPECT_EQ(test::configErrorOf([&] { l.set("net.widths", YAML::Load("64")); }).key(), "net.widths");  // a value for a list
  EXPECT_EQ(test::configErrorOf([&] { l.set("net", YAML::Load("3")); }).key(), "net");                 // a value for a map
  // A setting that passes the schema is read with the same checks as a file's value.
  for (const std::string v : {".nan", ".inf", "-.inf"}) {
    ConfigLayers fresh = layers();
    fresh.set("net.lr", YAML::Load(v));
    const ConfigError e = test::configErrorOf([&] { fresh.section("net").positive("lr"); });
    EXPECT_EQ(e.file(), "command line") << v;
    EXPECT_EQ(e.key(), "net.lr") << v;
    EXPECT_NE(text(e).find("finite"), std::string::npos) << text(e);
  }
}

TEST(ConfigLayers, ParseSettingRefusesWhatIsNotKeyEqualsYaml) {
  EXPECT_EQ(parseSetting("net.lr=1e-3").first, "net.lr");
  EXPECT_DOUBLE_EQ(parseSetting("net.lr=1e-3").second.as<double>(), 1e-3);
  EXPECT_EQ(test::configErrorOf([] { parseSetting("net.lr"); }).file(), "command line");
  EXPECT_EQ(test::configErrorOf([] { parseSetting("=3"); }).key(), "=3");
  EXPECT_EQ(test::configErrorOf([] { parseSetting("net.widths=[1, 2"); }).key(), "net.widths");
}

TEST(ConfigLayers, OpenSectionsMergeAndRenamedKeysAreReadUnderTheirNewName) {
  ConfigLayers l = layers();
  l.overlay(YAML::Load("env: {weights: {alive: 1}}\nnet: {rate: 0.1}"), "task.yaml");
  l.set("env.weights.speed", YAML::Load("2"));
  EXPECT_EQ(l.tree()["env"]["weights"]["alive"].as<int>(), 1);
  EXPECT_EQ(l.tree()["env"]["weights"]["speed"].as<int>(), 2);
  EXPECT_DOUBLE_EQ(l.section("net").positive("lr"), 0.1);
  EXPECT_EQ(l.section("net").originOf("lr"), "task.yaml");
}

TEST(ConfigLayers, LoadYamlFileNamesAMissingFileAndTheLineOfASyntaxError) {
  const std::string dir = testing::TempDir();
  EXPECT_EQ(test::configErrorOf([&] { loadYamlFile(dir + "/no_such.yaml"); }).file(), dir + "/no_such.yaml");
  const std::string bad = dir + "/bad_config_section.yaml";
  std::ofstream(bad) << "a: 1\nb: [1, 2\n";
  const ConfigError e = test::configErrorOf([&] { loadYamlFile(bad); });
  EXPECT_EQ(e.file(), bad);
  EXPECT_NE(text(e).find("line"), std::string::npos) << text(e);
}

TEST(ConfigSection, EveryErrorNamesTheKeyPathAndWhereTheValueCameFrom) {
  ConfigLayers l = layers();
  l.overlay(YAML::Load("net: {gamma: 2}"), "task.yaml");
  l.set("net.steps", YAML::Load("0"));
  const ConfigSection net = l.section("net");
  const ConfigError from_file = test::configErrorOf([&] { net.inRange("gamma", 0.0, 1.0); });
  EXPECT_EQ(from_file.file(), "task.yaml");
  EXPECT_EQ(from_file.key(), "net.gamma");
  EXPECT_NE(text(from_file).find("must be in [0, 1], got 2"), std::string::npos) << text(from_file);
  const ConfigError from_line = test::configErrorOf([&] { net.atLeast("steps", 1); });
  EXPECT_EQ(from_line.file(), "command line");
  EXPECT_NE(text(from_line).find("must be at least 1, got 0"), std::string::npos) << text(from_line);
  // A key no layer set comes from the defaults.
  EXPECT_EQ(test::configErrorOf([&] { net.oneOf("mode", {"slow", "safe"}); }).file(), "defaults.yaml");
  EXPECT_EQ(l.section().section("net").path("lr"), "net.lr");
}

TEST(ConfigSection, NaNAndInfinityAreRefusedByEveryNumericRead) {
  for (const std::string v : {".nan", ".inf", "-.inf", ".NaN", "-.Inf"}) {
    ConfigLayers l = layers();
    l.set("net.lr", YAML::Load(v));
    l.set("net.pose", YAML::Load("[0.1, " + v + "]"));
    const ConfigSection net = l.section("net");
    const std::vector<std::function<void()>> reads = {
        [&] { net.number("lr"); },
        [&] { net.positive("lr"); },
        [&] { net.nonNegative("lr"); },
        [&] { net.inRange("lr", -1e300, 1e300); },
        [&] { net.get<double>("lr", "a number"); },
        [&] { net.get<float>("lr", "a number"); },
        [&] { net.get<std::vector<double>>("pose", "angles"); },
    };
    for (size_t i = 0; i < reads.size(); ++i) {
      const ConfigError e = test::configErrorOf(reads[i]);
      EXPECT_EQ(e.file(), "command line") << v << " read " << i;
      EXPECT_NE(text(e).find("finite"), std::string::npos) << v << " read " << i << ": " << text(e);
    }
    // Integer reads take no NaN either (yaml-cpp does not convert it).
    EXPECT_EQ(test::configErrorOf([&] { net.atLeast("lr", 0); }).key(), "net.lr") << v;
    EXPECT_EQ(test::configErrorOf([&] { net.integerIn("lr", 0, 9); }).key(), "net.lr") << v;
  }
}

TEST(ConfigSection, RangesAndTheirEnds) {
  const auto read = [](const std::string& value) {
    ConfigLayers l = layers();
    l.set("net.lr", YAML::Load(value));
    return l.section("net");
  };
  EXPECT_DOUBLE_EQ(read("0.5").positive("lr"), 0.5);
  EXPECT_NE(text(test::configErrorOf([&] { read("0").positive("lr"); })).find("must be positive, got 0"), std::string::npos);
  EXPECT_DOUBLE_EQ(read("0").nonNegative("lr"), 0.0);
  EXPECT_NE(text(test::configErrorOf([&] { read("-1e-3").nonNegative("lr"); })).find("must not be negative, got -0.001"),
            std::string::npos);
  EXPECT_DOUBLE_EQ(read("1").inRange("lr", 0, 1, true), 1.0);  // (0, 1]
  EXPECT_NE(text(test::configErrorOf([&] { read("0").inRange("lr", 0, 1, true); })).find("must be in (0, 1], got 0"),
            std::string::npos);
  EXPECT_NE(text(test::configErrorOf([&] { read("1").inRange("lr", 0, 1, true, true); })).find("must be in (0, 1), got 1"),
            std::string::npos);
  EXPECT_DOUBLE_EQ(read("0").inRange("lr", 0, 1), 0.0);  // [0, 1]
  EXPECT_EQ(read("7").atLeast("lr", 7), 7);
  EXPECT_EQ(read("5000000000").atLeast("lr", 1LL), 5000000000LL);
  EXPECT_NO_THROW(read("5000000000").atLeast("lr", 1LL));
  EXPECT_THROW(read("5000000000").atLeast("lr", 1), ConfigError);  // not an int
  EXPECT_EQ(read("9").integerIn("lr", 0, 9), 9);
  EXPECT_NE(text(test::configErrorOf([&] { read("10").integerIn("lr", 0, 9); })).find("must be in [0, 9], got 10"),
            std::string::npos);
}

TEST(ConfigSection, AWrongTypeIsRefusedWithWhatWasExpected) {
  ConfigLayers l = layers();
  l.overlay(YAML::Load("net: {lr: fast, steps: 1.5, on: maybe, widths: [64, 0], mode: slow}"), "t.yaml");
  const ConfigSection net = l.section("net");
  EXPECT_NE(text(test::configErrorOf([&] { net.number("lr"); })).find("expected a number, got 'fast'"), std::string::npos);
  EXPECT_NE(text(test::configErrorOf([&] { net.atLeast("steps", 0); })).find("expected an integer, got '1.5'"), std::string::npos);
  EXPECT_NE(text(test::configErrorOf([&] { net.get<bool>("on", "true or false"); })).find("expected true or false"),
            std::string::npos);
  EXPECT_NE(text(test::configErrorOf([&] { net.widths("widths"); })).find("layer widths must be positive, got 0"),
            std::string::npos);
  EXPECT_NE(text(test::configErrorOf([&] { net.oneOf("mode", {"fast", "safe", "off"}); })).find("expected fast, safe or off, got 'slow'"),
            std::string::npos);
  EXPECT_EQ(test::configErrorOf([&] { net.widths("widths"); }).file(), "t.yaml");
}

TEST(NearestName, FindsOneTypoAwayAndNothingFarAway) {
  const std::vector<std::string> known{"horizon", "gamma", "tau", "num_envs"};
  EXPECT_EQ(nearestName("horizn", known), "horizon");   // a deletion
  EXPECT_EQ(nearestName("gmama", known), "gamma");      // a swap
  EXPECT_EQ(nearestName("num_env", known), "num_envs");
  EXPECT_EQ(nearestName("tua", known), "tau");
  EXPECT_EQ(nearestName("xyz", known), "");
  EXPECT_EQ(nearestName("learning_rate", known), "");
}

}  // namespace
}  // namespace masa::config

namespace masa::config {
namespace {

// Issue #54 item 3: the task's `env` reader, the YAML task reader and the spec parser read values
// as the run config's reader does, with one error format: file, key path, why, and the line.
TEST(OneConfigReader, TheRunAndTaskReadersGiveTheSameErrorForTheSameBadValue) {
  const YAML::Node file = YAML::Load("env:\n  kp: fast\n  kd: .nan\n");
  const ConfigSection run(file, {}, "t.yaml", "env");
  task::EnvParams env(file["env"], {}, "t.yaml");
  for (const char* key : {"kp", "kd"}) {
    const ConfigError a = test::configErrorOf([&] { run.number(key); });
    const ConfigError b = test::configErrorOf([&] { env.number(key, 1.0); });
    EXPECT_EQ(std::string(a.what()), std::string(b.what())) << key;
    EXPECT_EQ(b.key(), std::string("env.") + key);
    EXPECT_EQ(b.file(), "t.yaml");
    EXPECT_NE(std::string(b.what()).find("(line "), std::string::npos) << b.what();
  }
  const ConfigError range = test::configErrorOf([&] { env.positive("kp_missing", -1.0); });
  EXPECT_NE(std::string(range.what()).find("must be positive, got -1"), std::string::npos) << range.what();
}

}  // namespace
}  // namespace masa::config
