// The run directory's learning_curve.png, drawn from metrics.csv by gnuplot (Debian's gnuplot-nox).
//
// The learner writes learning_curve.gp next to metrics.csv (a user can edit and re-run it) and runs
// gnuplot in the background so that training never waits for a plot: a render still running when
// the next is due is simply skipped. The PNG is written to a temporary file and renamed, so a
// reader never sees half a picture. Without gnuplot the learner warns once and trains on.
#pragma once

#include <string>
#include <sys/types.h>
#include <vector>

namespace masa::learner {

class LearningCurve {
 public:
  // term_names: the task's reward terms, as the metrics.csv columns term_<name>; has_success: the
  // task measures success (Task::hasSuccessMeasure), so the length panel gets a success axis.
  LearningCurve(std::string run_dir, std::string title, std::vector<std::string> term_names, bool has_success = true);
  // A run whose metrics.csv has other columns (masa_offline's): its own script, rendered the same way.
  struct Script {
    std::string text;
  };
  LearningCurve(std::string run_dir, const Script& script);
  ~LearningCurve();  // waits for a render in flight
  LearningCurve(const LearningCurve&) = delete;
  LearningCurve& operator=(const LearningCurve&) = delete;

  // Starts a render unless one is still running; never blocks.
  void renderAsync();
  // Renders now and waits (at the end of a run). Returns true when the PNG was written.
  bool renderAndWait();

  const std::string& scriptPath() const { return script_; }
  const std::string& pngPath() const { return png_; }

 private:
  void writeScript(const std::vector<std::string>& term_names, const std::string& title, bool has_success) const;
  bool reap(bool block);  // true when no render is running afterwards
  bool spawn();

  std::string dir_, script_, png_;
  pid_t child_ = -1;
  int last_status_ = 0;
  bool gnuplot_missing_ = false;
};

// What every run's curve script shares: the 2 x 3 PNG page titled `title` with `xlabel` under each
// panel (header; `what` and `writer` name the run and the program in its comment), and the rename
// that publishes the picture whole (footer).
std::string curveScriptHeader(const std::string& what, const std::string& writer, const std::string& title,
                              const std::string& xlabel);
std::string curveScriptFooter();
// A gnuplot double-quoted string of the characters that can neither end it, run a command
// (`backquotes`) nor expand a macro (@): letters, digits and " _-+./:,()[]=%#"; the rest dropped.
std::string gnuplotQuoted(const std::string& s);

// gnuplot script text for a metrics.csv with these reward terms (exposed for tests).
// ppo_panels false (learner: off_policy): the KL and learning-rate panel, both 0 there (on a log
// scale gnuplot finds no point and stops drawing), becomes one of the mean Q and the entropy from the
// run's off_policy.csv, and the throughput is on a log scale (the warm-up rounds are far faster).
std::string learningCurveScript(const std::string& title, const std::vector<std::string>& term_names,
                                bool has_success = true, bool ppo_panels = true);

}  // namespace masa::learner
