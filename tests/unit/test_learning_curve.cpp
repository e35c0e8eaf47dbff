// The run directory's learning_curve.png, rendered by gnuplot from metrics.csv.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "learner/run_dir/learning_curve.hpp"
#include "test_temp_dir.hpp"

namespace masa::learner {
namespace {

namespace fs = std::filesystem;

fs::path freshCurveDir(const std::string& name) { return masa::testing::freshTempDir("masa_test_curve_" + name); }

// A metrics.csv as the learner writes it, with one update in which no episode ended (nan) and an
// evaluation of the policy mean every other update (nan between).
void writeMetrics(const fs::path& dir, int rows) {
  std::ofstream f(dir / "metrics.csv");
  f << "update,env_steps,wall_time_s,fps,return,length,success,term_alive,term_velocity,actor_loss,"
       "critic_loss,entropy,bounds_loss,sym_policy,sym_value,kl,lr,grad_norm,explained_variance,dropped_chunks,"
       "dropped_envs,eval_return,eval_length,eval_success,eval_distance_m\n";
  for (int i = 0; i < rows; ++i) {
    const bool ended = i != 1;
    f << i + 1 << ',' << (i + 1) * 2048 << ',' << i * 0.5 << ",4000,";
    if (ended)
      f << 10.0 + i << ',' << 20 + i << ",-1," << 0.5 * i << ',' << 1.0 + i;
    else
      f << "nan,nan,-1,nan,nan";
    f << ",-0.01,0.5,1.2,0,0,0,0.002,0.0005,0.8,0.3,0,0";
    if (i % 2 == 0)
      f << ',' << 12.0 + i << ',' << 25 + i << ",nan," << 0.1 * i << '\n';
    else
      f << ",nan,nan,nan,nan\n";
  }
}

bool isPng(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  char magic[8] = {};
  f.read(magic, 8);
  return f && std::string(magic + 1, 3) == "PNG";
}

bool haveGnuplot() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

TEST(LearningCurve, RendersAPngFromMetricsWithEveryRewardTerm) {
  if (!haveGnuplot()) GTEST_SKIP() << "gnuplot is not installed (scripts/install_deps.sh installs gnuplot-nox)";
  const fs::path dir = freshCurveDir("render");
  writeMetrics(dir, 6);
  LearningCurve curve(dir.string(), "a1_beam / masa", {"alive", "velocity"});
  const std::string script = [&] {
    std::ifstream f(curve.scriptPath());
    return std::string(std::istreambuf_iterator<char>(f), {});
  }();
  EXPECT_NE(script.find("\"alive velocity\""), std::string::npos) << "the terms panel plots every reward term";
  ASSERT_TRUE(curve.renderAndWait()) << "gnuplot log: " << (dir / "learning_curve.log");
  EXPECT_TRUE(isPng(curve.pngPath()));
  EXPECT_GT(fs::file_size(curve.pngPath()), 10000u);  // six panels, not an empty canvas
  EXPECT_FALSE(fs::exists(dir / "learning_curve.png.tmp"));
  fs::remove_all(dir);
}

// Issue #31: the env-step ticks ran together ("1e+062e+06..."), legends lay over the curves, and a
// task without success (the A1) had a success axis.
// learner: off_policy writes 0 for kl and lr (and TD3 NaN for the entropy): PPO's log-scale KL panel
// has no point, gnuplot stopped there and no picture came; the off-policy panels draw.
TEST(LearningCurve, AnOffPolicyRunWithZeroKlAndLearningRateIsDrawnWithItsOwnPanels) {
  if (!haveGnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const fs::path dir = freshCurveDir("off_policy");
  {
    std::ofstream f(dir / "metrics.csv");
    f << "update,env_steps,wall_time_s,fps,return,length,success,term_alive,actor_loss,critic_loss,entropy,"
         "bounds_loss,sym_policy,sym_value,kl,lr,grad_norm,explained_variance,dropped_chunks,dropped_envs,"
         "eval_return,eval_length,eval_success\n";
    for (int i = 0; i < 5; ++i)
      f << i + 1 << ',' << (i + 1) * 512 << ",1,500," << 5 + i << ",30,-1,1," << -i << ',' << 2.0 / (i + 1)
        << ",nan,0,0,0,0,0,0,0,0,0,nan,nan,nan\n";
  }
  {
    std::ofstream f(dir / "off_policy.csv");  // the learner's, before every render; TD3: entropy nan
    f << "update,env_steps,policy_lag_mean,policy_lag_max,gradient_steps,gradient_steps_total,replay_size,"
         "warming_up,q_loss,actor_loss,alpha_loss,symmetry_loss,alpha,mean_q,entropy\n";
    for (int i = 0; i < 5; ++i)
      f << i + 1 << ',' << (i + 1) * 512 << ",0,0,128,128,512,0,1,-1,0,0,0," << 10 + i << ",nan\n";
  }
  const std::string script = learningCurveScript("a1_beam / masa", {"alive"}, false, false);
  EXPECT_NE(script.find("\"off_policy.csv\" using (column(\"env_steps\")/1e6):\"mean_q\""), std::string::npos)
      << "the off-policy panel draws the mean Q";
  EXPECT_EQ(script.find("title \"twin-Q loss\""), std::string::npos) << "the critic loss is drawn once, in the losses";
  {
    LearningCurve ppo(dir.string(), "a1_beam / masa", {"alive"}, false);
    EXPECT_FALSE(ppo.renderAndWait()) << "PPO's KL panel cannot be drawn from zeros: the case this guards";
  }
  LearningCurve off(dir.string(), LearningCurve::Script{script});
  ASSERT_TRUE(off.renderAndWait()) << "gnuplot log: " << (dir / "learning_curve.log");
  EXPECT_TRUE(isPng(off.pngPath()));
  fs::remove_all(dir);
}

TEST(LearningCurve, StepsInMillionsLegendsBelowTheDataAndASuccessAxisOnlyWhereTheTaskHasOne) {
  const std::string with = learningCurveScript("trifinger_lift / masa", {"alive"}, true);
  const std::string without = learningCurveScript("a1_beam / masa", {"alive"}, false);
  for (const std::string* s : {&with, &without}) {
    EXPECT_NE(s->find("env steps (millions)"), std::string::npos);
    EXPECT_EQ(s->find("using \"env_steps\""), std::string::npos) << "every panel's x is in millions";
    EXPECT_NE(s->find("set key below"), std::string::npos);
    EXPECT_EQ(s->find("set key top"), std::string::npos);
  }
  EXPECT_NE(with.find("success"), std::string::npos);
  EXPECT_NE(with.find("y2tics"), std::string::npos);
  EXPECT_EQ(without.find("success"), std::string::npos) << without;
  EXPECT_EQ(without.find("y2"), std::string::npos);
  if (!haveGnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  for (bool has_success : {true, false}) {
    const fs::path dir = freshCurveDir(has_success ? "with_success" : "without_success");
    writeMetrics(dir, 6);
    LearningCurve curve(dir.string(), "a1_beam / masa", {"alive", "velocity"}, has_success);
    EXPECT_TRUE(curve.renderAndWait()) << "gnuplot log: " << (dir / "learning_curve.log");
    EXPECT_TRUE(isPng(curve.pngPath()));
    fs::remove_all(dir);
  }
}

TEST(LearningCurve, AsyncRenderDoesNotBlockAndIsCollectedByTheDestructor) {
  if (!haveGnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const fs::path dir = freshCurveDir("async");
  writeMetrics(dir, 4);
  {
    LearningCurve curve(dir.string(), "t", {"alive", "velocity"});
    curve.renderAsync();
    curve.renderAsync();  // skipped while the first is running, or a second render: either is fine
  }
  EXPECT_TRUE(isPng(dir / "learning_curve.png"));
  fs::remove_all(dir);
}

TEST(LearningCurve, ABrokenMetricsFileFailsTheRenderInsteadOfWritingAPicture) {
  if (!haveGnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const fs::path dir = freshCurveDir("broken");
  std::ofstream(dir / "metrics.csv") << "not,the,columns\n1,2,3\n";
  LearningCurve curve(dir.string(), "t", {"alive"});
  EXPECT_FALSE(curve.renderAndWait());
  EXPECT_FALSE(fs::exists(curve.pngPath()));
  fs::remove_all(dir);
}

TEST(LearningCurve, WithoutGnuplotTheRenderReportsFailureAndTrainingGoesOn) {
  const fs::path dir = freshCurveDir("missing");
  writeMetrics(dir, 3);
  const char* old_path = std::getenv("PATH");
  const std::string saved = old_path ? old_path : "";
  ::setenv("PATH", dir.c_str(), 1);  // a PATH without gnuplot
  {
    LearningCurve curve(dir.string(), "t", {"alive"});
    EXPECT_FALSE(curve.renderAndWait());
    curve.renderAsync();  // warned once already: a no-op
  }
  ::setenv("PATH", saved.c_str(), 1);
  EXPECT_FALSE(fs::exists(dir / "learning_curve.png"));
  fs::remove_all(dir);
}

// docs/inputs.md gap 1: gnuplot runs `commands` inside double-quoted strings and expands @macros;
// whatever a name holds, the script carries neither, and rendering runs nothing.
TEST(LearningCurve, NamesCannotRunACommandOrAMacroInTheScript) {
  const fs::path marker = fs::temp_directory_path() / "masa_gnuplot_injected";
  fs::remove(marker);
  const std::string evil = "`touch " + marker.string() + "`";
  const std::string script = learningCurveScript("a1_beam / masa @evil \" \\ $x", {evil, "alive"}, false);
  EXPECT_EQ(script.find('`'), std::string::npos) << script;
  EXPECT_EQ(script.find("@evil"), std::string::npos);
  EXPECT_EQ(gnuplotQuoted("a1_beam / masa, seed 7 (x1.5) [10%]"), "\"a1_beam / masa, seed 7 (x1.5) [10%]\"")
      << "ordinary titles pass unchanged";
  if (!haveGnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const fs::path dir = freshCurveDir("injection");
  writeMetrics(dir, 4);
  LearningCurve curve(dir.string(), "a1_beam / masa", {evil, "alive"}, false);
  curve.renderAndWait();
  EXPECT_FALSE(fs::exists(marker)) << "gnuplot ran the name's command";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace masa::learner
