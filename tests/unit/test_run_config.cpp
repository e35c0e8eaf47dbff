// Run configuration: the paper's values per task, overrides, and errors that name file and key.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/config/run_config.hpp"
#include "common/core/config_error.hpp"

namespace masa::config {
namespace {
namespace fs = std::filesystem;

const std::string kConfigs = std::string(MASA_SOURCE_DIR) + "/configs";

// A scratch configs dir with the real defaults and one task file of our own.
class ScratchConfigs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("masa_cfg_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_ / "tasks");
    fs::copy_file(kConfigs + "/defaults.yaml", dir_ / "defaults.yaml");
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string writeTask(const std::string& name, const std::string& text) {
    const auto p = dir_ / "tasks" / (name + ".yaml");
    std::ofstream(p) << text;
    return p.string();
  }
  ConfigError expectError(const std::vector<std::string>& overrides) {
    try {
      loadRunConfig(dir_.string(), overrides);
    } catch (const ConfigError& e) {
      return e;
    }
    ADD_FAILURE() << "expected a ConfigError";
    return ConfigError("", "", "");
  }
  fs::path dir_;
};

TEST(RunConfig, EveryShippedTaskLoadsWithThePapersHyperparameters) {
  struct Want {
    const char* task;
    int envs, horizon, minibatch, epochs;
    double lr, critic;
    int width0;
  };
  const Want wants[] = {{"humanoid_tightrope", 4096, 32, 32768, 5, 5e-4, 4.0, 400},
                        {"humanoid_dribbling", 4096, 32, 32768, 5, 5e-4, 4.0, 400},
                        {"trifinger_lift", 16384, 16, 16384, 4, 3e-4, 4.0, 256},
                        {"a1_beam", 4096, 24, 32768, 5, 3e-4, 2.0, 256},
                        {"ant_acrobatic", 4096, 16, 32768, 4, 3e-4, 2.0, 256}};
  for (const auto& w : wants) {
    const RunConfig c = loadRunConfig(kConfigs, {std::string("task=") + w.task});
    EXPECT_EQ(c.task, w.task);
    EXPECT_EQ(c.rollout.num_envs, w.envs) << w.task;
    EXPECT_EQ(c.rollout.horizon, w.horizon) << w.task;
    EXPECT_EQ(c.ppo.minibatch_size, w.minibatch) << w.task;
    EXPECT_EQ(c.ppo.mini_epochs, w.epochs) << w.task;
    EXPECT_DOUBLE_EQ(c.ppo.learning_rate, w.lr) << w.task;
    EXPECT_DOUBLE_EQ(c.ppo.critic_coef, w.critic) << w.task;
    EXPECT_EQ(c.model.policy_hidden.front(), w.width0) << w.task;
    EXPECT_DOUBLE_EQ(c.ppo.kl_threshold, 0.0008);
    EXPECT_DOUBLE_EQ(c.ppo.gamma, 0.99);
    EXPECT_DOUBLE_EQ(c.ppo.tau, 0.95);
    EXPECT_DOUBLE_EQ(c.ppo.e_clip, 0.2);
    EXPECT_TRUE(fs::exists(c.spec_path)) << c.spec_path;
  }
}

TEST(RunConfig, CommandLineOverridesTaskFileWhichOverridesDefaults) {
  const RunConfig c = loadRunConfig(kConfigs, {"task=a1_beam", "method=SASA", "ppo.horizon=8",
                                               "model.policy_hidden=[64, 32]", "seed=17", "env.target_speed=0.5"});
  EXPECT_EQ(c.method, model::Method::kSasa);
  EXPECT_EQ(c.rollout.horizon, 8);
  EXPECT_EQ(c.model.policy_hidden, (std::vector<int>{64, 32}));
  EXPECT_EQ(c.seed, 17u);
  EXPECT_DOUBLE_EQ(c.env["target_speed"].as<double>(), 0.5);
  EXPECT_EQ(c.origin.at("ppo.horizon"), "command line");
  EXPECT_NE(c.origin.at("ppo.learning_rate").find("a1_beam.yaml"), std::string::npos);
  EXPECT_NE(dumpResolved(c).find("horizon: 8"), std::string::npos);
}

TEST_F(ScratchConfigs, EnvSectionsMergeAcrossTaskFileAndCommandLine) {
  writeTask("t", "env:\n  episode_steps: 100\n  weights: {alive: 2.0, velocity: 1.0}\n");
  const RunConfig c = loadRunConfig(dir_.string(), {"task=t", "env.weights.alive=0.5"});
  EXPECT_EQ(c.env["episode_steps"].as<int>(), 100);
  EXPECT_DOUBLE_EQ(c.env["weights"]["alive"].as<double>(), 0.5);
  EXPECT_DOUBLE_EQ(c.env["weights"]["velocity"].as<double>(), 1.0);
}

// The update has one name (issue #32): ppo.max_updates. Files written before, run directories
// and policy files among them, say ppo.max_epochs, which is read as the same key.
TEST_F(ScratchConfigs, TheOldNameMaxEpochsIsReadAsMaxUpdates) {
  writeTask("t", "ppo:\n  max_epochs: 7\n");
  const RunConfig c = loadRunConfig(dir_.string(), {"task=t"});
  EXPECT_EQ(c.rollout.max_updates, 7);
  EXPECT_EQ(loadRunConfig(dir_.string(), {"task=t", "ppo.max_epochs=9"}).rollout.max_updates, 9);
  EXPECT_EQ(loadRunConfig(dir_.string(), {"task=t", "ppo.max_updates=11"}).rollout.max_updates, 11);
  EXPECT_EQ(dumpResolved(c).find("max_epochs"), std::string::npos);
}

// Issue #54: an algorithm is sized by its own section. The off-policy learner's rounds are
// sac.num_envs x sac.horizon transitions, sac.env_steps of them in all; PPO's batch is ppo.*.
TEST_F(ScratchConfigs, EachLearnerIsSizedByItsOwnSection) {
  writeTask("t", "");
  const RunConfig ppo = loadRunConfig(dir_.string(), {"task=t", "ppo.num_envs=8", "ppo.horizon=4", "ppo.max_updates=5"});
  EXPECT_EQ(ppo.rollout.section, "ppo");
  EXPECT_EQ(ppo.rollout.num_envs, 8);
  EXPECT_EQ(ppo.rollout.horizon, 4);
  EXPECT_EQ(ppo.rollout.max_updates, 5);
  const RunConfig off = loadRunConfig(dir_.string(), {"task=t", "learner=off_policy", "sac.num_envs=8", "sac.horizon=4",
                                                      "sac.env_steps=100", "sac.max_policy_lag=1"});
  EXPECT_EQ(off.rollout.section, "sac");
  EXPECT_EQ(off.rollout.num_envs, 8);
  EXPECT_EQ(off.rollout.horizon, 4);
  EXPECT_EQ(off.rollout.max_updates, 4) << "100 env steps are 4 rounds of 32, the last one short";
  EXPECT_EQ(off.rollout.max_policy_lag, 1);
  EXPECT_EQ(off.rollout.key("num_envs"), "sac.num_envs");
}

// A PPO sizing key given to an off-policy run would be ignored; it is refused, naming the key to set.
TEST_F(ScratchConfigs, APpoSizingKeyGivenToTheOffPolicyLearnerIsRefusedNamingItsOwn) {
  writeTask("t", "");
  for (const auto& [set, own] : std::vector<std::pair<std::string, std::string>>{
           {"ppo.num_envs=8", "sac.num_envs"}, {"ppo.horizon=4", "sac.horizon"},
           {"ppo.max_updates=5", "sac.env_steps"}, {"ppo.max_policy_lag=1", "sac.max_policy_lag"}}) {
    try {
      loadRunConfig(dir_.string(), {"task=t", "learner=off_policy", set});
      ADD_FAILURE() << set << " was accepted for learner off_policy";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), set.substr(0, set.find('=')));
      EXPECT_EQ(e.file(), "command line");
      EXPECT_NE(std::string(e.what()).find(own), std::string::npos) << e.what();
    }
  }
  // A task file's PPO batch sizes the task's PPO runs and does not stand in the way of off-policy ones.
  writeTask("u", "ppo:\n  num_envs: 16384\n  horizon: 8\n");
  const RunConfig u = loadRunConfig(dir_.string(), {"task=u", "learner=off_policy"});
  EXPECT_EQ(u.rollout.num_envs, 64);
  EXPECT_EQ(u.rollout.horizon, 16);
}

// Run directories and policy files written before (off-policy sized by ppo.*) read as they were
// meant, and are written back in the new form, which reads the same.
TEST_F(ScratchConfigs, AnOldOffPolicyRunConfigIsReadWithItsPpoSizing) {
  writeTask("t", "");
  const fs::path old = dir_ / "config.yaml";
  std::ofstream(old) << "task: t\nlearner: off_policy\nppo:\n  num_envs: 64\n  horizon: 16\n  max_updates: 5500\n"
                        "  max_policy_lag: 1\nsac:\n  env_steps: 1000000\n  algorithm: td3\n";
  const RunConfig c = loadRunConfig(dir_.string(), {}, old.string());
  EXPECT_EQ(c.rollout.section, "sac");
  EXPECT_EQ(c.rollout.num_envs, 64);
  EXPECT_EQ(c.rollout.horizon, 16);
  EXPECT_EQ(c.rollout.max_updates, 5500);
  EXPECT_EQ(c.rollout.max_policy_lag, 1);
  const fs::path again = dir_ / "again.yaml";
  std::ofstream(again) << dumpResolved(c);
  const RunConfig d = loadRunConfig(dir_.string(), {}, again.string());
  EXPECT_EQ(d.rollout.num_envs, 64);
  EXPECT_EQ(d.rollout.horizon, 16);
  EXPECT_EQ(d.rollout.max_updates, 5500);
  EXPECT_EQ(d.rollout.max_policy_lag, 1);
  EXPECT_EQ(d.resolved["sac"]["algorithm"].as<std::string>(), "td3");
  // A PPO run's old config is PPO's, untouched.
  const fs::path old_ppo = dir_ / "ppo.yaml";
  std::ofstream(old_ppo) << "task: t\nppo:\n  num_envs: 64\n  horizon: 16\n";
  EXPECT_EQ(loadRunConfig(dir_.string(), {}, old_ppo.string()).rollout.num_envs, 64);
}

TEST_F(ScratchConfigs, UnknownKeyInTaskFileNamesTheFileAndTheKey) {
  const std::string file = writeTask("t", "ppo:\n  learning_rat: 0.1\n");
  const ConfigError e = expectError({"task=t"});
  EXPECT_EQ(e.file(), file);
  EXPECT_EQ(e.key(), "ppo.learning_rat");
  EXPECT_NE(std::string(e.what()).find("learning_rate"), std::string::npos) << "should list the known keys";
}

// An unknown task is named where it was written: the recipe or the command line, not the task
// file that does not exist (found by DamagedText: a damaged recipe's task named only a missing file).
TEST_F(ScratchConfigs, AnUnknownTaskIsNamedInTheRecipeOrOnTheCommandLineThatSetIt) {
  writeTask("t", "ppo:\n  horizon: 8\n");
  const fs::path recipe = dir_ / "r.yaml";
  std::ofstream(recipe) << "task: no_such\nppo:\n  horizon: 4\n";
  ConfigError e = expectError({"@" + recipe.string()});
  EXPECT_EQ(e.file(), recipe.string());
  EXPECT_EQ(e.key(), "task");
  EXPECT_NE(std::string(e.what()).find("unknown task 'no_such'"), std::string::npos) << e.what();
  e = expectError({"task=../t"});
  EXPECT_EQ(e.file(), "command line");
  std::ofstream(recipe) << "task: [a, b]\n";
  EXPECT_EQ(expectError({"@" + recipe.string()}).file(), recipe.string());
}

// A recipe is checked like a task file (docs/inputs.md gap 15): an unknown key, a map where a
// number belongs and a value out of range are each refused naming the recipe and the key.
TEST_F(ScratchConfigs, ABadRecipeIsRefusedNamingTheRecipeAndTheKey) {
  writeTask("t", "ppo:\n  horizon: 8\n");
  const fs::path recipe = dir_ / "bad_recipe.yaml";
  const struct {
    const char* text;
    const char* key;
  } cases[] = {{"task: t\nppo:\n  horizn: 4\n", "ppo.horizn"},
               {"task: t\nppo:\n  horizon: {a: 1}\n", "ppo.horizon"},
               {"task: t\nppo:\n  horizon: 0\n", "ppo.horizon"},
               {"task: t\nppo:\n  learning_rate: .nan\n", "ppo.learning_rate"}};
  for (const auto& c : cases) {
    std::ofstream(recipe) << c.text;
    const ConfigError e = expectError({"@" + recipe.string()});
    EXPECT_EQ(e.file(), recipe.string()) << c.text;
    EXPECT_EQ(e.key(), c.key) << c.text << ": " << e.what();
  }
}

TEST_F(ScratchConfigs, UnknownKeyOnCommandLineNamesCommandLine) {
  writeTask("t", "");
  const ConfigError e = expectError({"task=t", "ppo.horizn=3"});
  EXPECT_EQ(e.file(), "command line");
  EXPECT_EQ(e.key(), "ppo.horizn");
}

// docs/inputs.md gap 3: YAML spells NaN and infinity (.nan, .inf); a run setting of either used
// to be taken (the rollout then returned nan).
TEST_F(ScratchConfigs, NaNOrInfinityIsRefusedNamingTheKey) {
  writeTask("t", "");
  for (const std::string v : {".nan", ".inf", "-.inf"}) {
    const ConfigError e = expectError({"task=t", "model.init_log_std=" + v});
    EXPECT_EQ(e.key(), "model.init_log_std") << v;
    EXPECT_NE(std::string(e.what()).find("finite"), std::string::npos) << e.what();
  }
  const ConfigError lr = expectError({"task=t", "ppo.learning_rate=.inf"});  // positive() let infinity through
  EXPECT_EQ(lr.key(), "ppo.learning_rate");
}

TEST_F(ScratchConfigs, WrongTypeNamesWhereTheValueCameFrom) {
  const std::string file = writeTask("t", "ppo:\n  horizon: lots\n");
  const ConfigError e = expectError({"task=t"});
  EXPECT_EQ(e.file(), file);
  EXPECT_EQ(e.key(), "ppo.horizon");
}

TEST_F(ScratchConfigs, MapWhereAValueBelongsIsRejected) {
  const std::string file = writeTask("t", "ppo:\n  gamma: {a: 1}\n");
  EXPECT_EQ(expectError({"task=t"}).key(), "ppo.gamma");
}

TEST_F(ScratchConfigs, OutOfRangeValuesAreRejected) {
  writeTask("t", "");
  EXPECT_EQ(expectError({"task=t", "ppo.gamma=1.5"}).key(), "ppo.gamma");
  EXPECT_EQ(expectError({"task=t", "ppo.learning_rate=-1"}).key(), "ppo.learning_rate");
  EXPECT_EQ(expectError({"task=t", "ppo.mini_epochs=0"}).key(), "ppo.mini_epochs");
  EXPECT_EQ(expectError({"task=t", "model.policy_hidden=[]"}).key(), "model.policy_hidden");
  EXPECT_EQ(expectError({"task=t", "model.activation=swish"}).key(), "model.activation");
  EXPECT_EQ(expectError({"task=t", "method=qmix"}).key(), "method");
  EXPECT_EQ(expectError({"task=t", "ppo.lr_schedule=cosine"}).key(), "ppo.lr_schedule");
}

TEST_F(ScratchConfigs, UnknownTaskListsTheKnownOnes) {
  writeTask("walker", "");
  const ConfigError e = expectError({"task=runner"});
  EXPECT_EQ(e.key(), "task");
  EXPECT_NE(std::string(e.what()).find("walker"), std::string::npos) << e.what();
}

TEST_F(ScratchConfigs, MalformedYamlNamesFileAndLine) {
  const std::string file = writeTask("t", "ppo:\n  horizon: [1, 2\n");
  const ConfigError e = expectError({"task=t"});
  EXPECT_EQ(e.file(), file);
  EXPECT_NE(std::string(e.what()).find("line"), std::string::npos) << e.what();
}

TEST_F(ScratchConfigs, MalformedOverrideIsRejected) {
  writeTask("t", "");
  EXPECT_EQ(expectError({"task=t", "ppo.horizon"}).file(), "command line");
}

}  // namespace
}  // namespace masa::config
