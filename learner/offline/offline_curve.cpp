#include "learner/offline/offline_curve.hpp"

#include <sstream>

#include "learner/run_dir/learning_curve.hpp"

namespace masa::offline {
namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : " ") + n;
  return learner::gnuplotQuoted(s);
}

}  // namespace

std::string offlineCurveScript(const std::string& title, const std::vector<std::string>& losses,
                               const std::vector<std::string>& figures, bool evaluates) {
  std::ostringstream g;
  g << learner::curveScriptHeader("a masa offline run", "masa_offline", title, "gradient steps");
  if (evaluates) {
    g << "# Rows without an evaluation say nan there: evaluations are points.\n"
         "set title \"evaluation return (policy mean)\"\n"
         "plot \"metrics.csv\" using \"step\":\"eval_return\" with points pt 5 ps 1.2 title \"return\"\n"
         "set title \"evaluation success and episode length\"\n"
         "set ytics nomirror\n"
         "set y2tics\n"
         "set y2range [0:1]\n"
         "plot \"metrics.csv\" using \"step\":\"eval_length\" with points pt 7 ps 1.2 title \"length\", \\\n"
         "     \"\" using \"step\":(column(\"eval_success\") < 0 ? NaN : column(\"eval_success\")) with points axes x1y2 pt 5 ps 1.2 title \"success\"\n"
         "unset y2tics\n"
         "set ytics mirror\n";
  } else {
    // No evaluation column holds a number: plotting one would stop gnuplot ("all points y value
    // undefined") and no panel would be drawn. The two panels say why they are empty.
    g << "set xrange [0:1]\nset yrange [0:1]\nunset xtics\nunset ytics\n"
         "set label 1 \"no evaluation in this run\\n(offline.eval_every = 0, final_eval_episodes = 0)\" at graph 0.5,0.5 center\n"
         "set title \"evaluation return (policy mean)\"\n"
         "plot NaN notitle\n"
         "set title \"evaluation success and episode length\"\n"
         "plot NaN notitle\n"
         "unset label 1\nset autoscale\nset xtics\nset ytics\n";
  }
  g << "set title \"losses\"\n"
       "plot for [c in "
    << joined(losses)
    << "] \"metrics.csv\" using \"step\":(column(c)) pt 7 title c\n"
       "set title \"figures\"\n";
  if (figures.empty())
    g << "plot \"metrics.csv\" using \"step\":\"steps_per_s\" pt 7 title \"steps / s\"\n";
  else
    g << "plot for [c in " << joined(figures) << "] \"metrics.csv\" using \"step\":(column(c)) pt 7 title c\n";
  g << "set title \"throughput\"\n"
       "plot \"metrics.csv\" using \"step\":\"steps_per_s\" pt 7 title \"gradient steps / s\"\n"
    << learner::curveScriptFooter();
  return g.str();
}

}  // namespace masa::offline
