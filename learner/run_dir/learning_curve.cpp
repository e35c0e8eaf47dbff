#include "learner/run_dir/learning_curve.hpp"

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <spawn.h>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace masa::learner {

namespace fs = std::filesystem;

std::string gnuplotQuoted(const std::string& s) {
  // gnuplot runs `command` inside a double-quoted string and expands @macros: only characters that
  // can do neither pass (names of tasks, methods, terms, titles, labels are all of these).
  std::string out;
  for (char c : s)
    if (std::isalnum(static_cast<unsigned char>(c)) || std::strchr(" _-+./:,()[]=%#", c) != nullptr) out += c;
  return '"' + out + '"';
}

std::string curveScriptHeader(const std::string& what, const std::string& writer, const std::string& title,
                              const std::string& xlabel) {
  std::ostringstream g;
  g << "# Learning curves of " << what << ", drawn from metrics.csv (written by " << writer
    << ").\n"
       "# Re-render inside the run directory with: gnuplot learning_curve.gp\n"
       "set datafile separator \",\"\n"
       "set terminal pngcairo size 1500,900 font \",10\"\n"
       "set output \"learning_curve.png.tmp\"\n"
       "set termoption noenhanced  # task and term names have underscores, not subscripts\n"
       "set multiplot layout 2,3 title "
    << gnuplotQuoted(title)
    << "\n"
       "set grid\n"
       "# Legends under their panels, clear of the data.\n"
       "set key below horizontal\n"
       "set xlabel "
    << gnuplotQuoted(xlabel)
    << "\n"
       "set style data linespoints\n"
       "set pointsize 0.4\n";
  return g.str();
}

std::string curveScriptFooter() {
  return "unset multiplot\n"
         "set output\n"
         "# Renamed only when complete, so a viewer never sees half a picture.\n"
         "system(\"mv -f learning_curve.png.tmp learning_curve.png\")\n";
}

std::string learningCurveScript(const std::string& title, const std::vector<std::string>& term_names,
                                bool has_success, bool ppo_panels) {
  std::ostringstream g;
  std::string terms;
  for (const auto& t : term_names) terms += (terms.empty() ? "" : " ") + t;
  g << curveScriptHeader("a masa run", "masa_learner", title, "env steps (millions)")
    << "# Updates in which no episode ended have no return: the CSV says nan there.\n"
       "set title \"mean episode return\"\n"
       "plot \"metrics.csv\" using (column(\"env_steps\")/1e6):\"return\" pt 7 lw 2 title \"return (training)\", \\\n"
       "     \"\" using (column(\"env_steps\")/1e6):\"eval_return\" with points pt 5 ps 0.9 title \"return (policy mean)\"\n";
  if (has_success)
    g << "set title \"mean episode length and success rate\"\n"
         "set ytics nomirror\n"
         "set y2tics\n"
         "set y2range [0:1]\n"
         "plot \"metrics.csv\" using (column(\"env_steps\")/1e6):\"length\" pt 7 title \"length\", \\\n"
         "     \"\" using (column(\"env_steps\")/1e6):(column(\"success\") < 0 ? NaN : column(\"success\")) axes x1y2 pt 7 title \"success\"\n"
         "unset y2tics\n"
         "set ytics mirror\n";
  else  // a task without a success measure (A1, humanoids, ant) gets no success axis
    g << "set title \"mean episode length\"\n"
         "plot \"metrics.csv\" using (column(\"env_steps\")/1e6):\"length\" pt 7 title \"length\"\n";
  g << "set title \"reward terms (mean per episode)\"\n"
       "set key font \",8\"\n";
  if (term_names.empty())
    g << "plot \"metrics.csv\" using (column(\"env_steps\")/1e6):\"return\" pt 7 title \"return\"\n";
  else
    g << "plot for [t in " << gnuplotQuoted(terms) << "] \"metrics.csv\" using (column(\"env_steps\")/1e6):(column(\"term_\".t)) pt 7 title t\n";
  g << "set key font \",10\"\n"
       "set title \"losses\"\n"
       "plot \"metrics.csv\" using (column(\"env_steps\")/1e6):\"actor_loss\" pt 7 title \"actor\", \\\n"
       "     \"\" using (column(\"env_steps\")/1e6):\"critic_loss\" pt 7 title \"critic\"\n";
  if (!ppo_panels)  // the learner's off_policy.csv (written before every render); TD3's entropy is NaN
    g << "set title \"mean Q and policy entropy (off_policy.csv)\"\n"
         "plot \"off_policy.csv\" using (column(\"env_steps\")/1e6):\"mean_q\" pt 7 title \"mean Q\", \\\n"
         "     \"\" using (column(\"env_steps\")/1e6):\"entropy\" pt 7 title \"entropy (SAC)\"\n";
  else
    g << "set title \"KL and learning rate\"\n"
       "set logscale y\n"
       "plot \"metrics.csv\" using (column(\"env_steps\")/1e6):\"kl\" pt 7 title \"KL(old||new)\", \\\n"
       "     \"\" using (column(\"env_steps\")/1e6):\"lr\" pt 7 title \"learning rate\"\n"
       "unset logscale y\n";
  if (!ppo_panels)  // the first rounds collect without gradient steps, 10-30x faster than the rest
    g << "set title \"throughput (log scale: learning starts after the first rounds)\"\n"
         "set logscale y\n";
  else
    g << "set title \"throughput\"\n";
  g << "plot \"metrics.csv\" using (column(\"env_steps\")/1e6):\"fps\" pt 7 title \"env steps / s\"\n"
    << curveScriptFooter();
  return g.str();
}

LearningCurve::LearningCurve(std::string run_dir, std::string title, std::vector<std::string> term_names,
                             bool has_success)
    : dir_(std::move(run_dir)) {
  script_ = (fs::path(dir_) / "learning_curve.gp").string();
  png_ = (fs::path(dir_) / "learning_curve.png").string();
  writeScript(term_names, title, has_success);
}

LearningCurve::LearningCurve(std::string run_dir, const Script& script) : dir_(std::move(run_dir)) {
  script_ = (fs::path(dir_) / "learning_curve.gp").string();
  png_ = (fs::path(dir_) / "learning_curve.png").string();
  std::ofstream(script_) << script.text;
}

LearningCurve::~LearningCurve() { reap(true); }

void LearningCurve::writeScript(const std::vector<std::string>& term_names, const std::string& title,
                                bool has_success) const {
  std::ofstream(script_) << learningCurveScript(title, term_names, has_success);
}

bool LearningCurve::reap(bool block) {
  if (child_ < 0) return true;
  int status = 0;
  const pid_t r = ::waitpid(child_, &status, block ? 0 : WNOHANG);
  if (r == 0) return false;  // still running
  child_ = -1;
  last_status_ = r < 0 ? -1 : status;
  if (r > 0 && !(WIFEXITED(status) && WEXITSTATUS(status) == 0))
    std::cerr << "masa_learner: gnuplot failed to render " << png_ << " (run 'gnuplot learning_curve.gp' in the run "
              << "directory to see why)\n";
  return true;
}

bool LearningCurve::spawn() {
  if (gnuplot_missing_) return false;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addchdir_np(&actions, dir_.c_str());  // the script names files relative to the run
  // gnuplot's own chatter (warnings about empty columns early in a run) stays out of the progress output.
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "learning_curve.log", O_WRONLY | O_CREAT | O_TRUNC, 0644);
  char arg0[] = "gnuplot", arg1[] = "learning_curve.gp";
  char* argv[] = {arg0, arg1, nullptr};
  pid_t pid = -1;
  const int err = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) {
    gnuplot_missing_ = true;
    std::cerr << "masa_learner: cannot run gnuplot (" << std::strerror(err) << "): no learning_curve.png; install "
              << "it with scripts/install_deps.sh (package gnuplot-nox)\n";
    return false;
  }
  child_ = pid;
  return true;
}

void LearningCurve::renderAsync() {
  if (reap(false)) spawn();
}

bool LearningCurve::renderAndWait() {
  reap(true);
  std::error_code ec;
  const auto before = fs::exists(png_, ec) ? fs::last_write_time(png_, ec) : fs::file_time_type::min();
  if (!spawn()) return false;
  reap(true);
  return last_status_ == 0 && fs::exists(png_, ec) && fs::last_write_time(png_, ec) >= before;
}

}  // namespace masa::learner
