#include "learner/offline/offline_curve.hpp"

#include <sstream>

namespace masa::offline {
namespace {

std::string quoted(const std::string& s) {
  std::string out;
  for (char c : s)
    if (c != '"' && c != '\\' && c != '\n') out += c;
  return '"' + out + '"';
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : " ") + n;
  return quoted(s);
}

}  // namespace

std::string offlineCurveScript(const std::string& title, const std::vector<std::string>& losses,
                               const std::vector<std::string>& figures) {
  std::ostringstream g;
  g << "# Learning curves of a masa offline run, drawn from metrics.csv (written by masa_offline).\n"
       "# Re-render inside the run directory with: gnuplot learning_curve.gp\n"
       "set datafile separator \",\"\n"
       "set terminal pngcairo size 1500,900 font \",10\"\n"
       "set output \"learning_curve.png.tmp\"\n"
       "set termoption noenhanced\n"
       "set multiplot layout 2,3 title "
    << quoted(title)
    << "\n"
       "set grid\n"
       "set key top left\n"
       "set xlabel \"gradient steps\"\n"
       "set style data linespoints\n"
       "set pointsize 0.4\n"
       "# Rows without an evaluation say nan there.\n"
       "set title \"evaluation return (policy mean)\"\n"
       "plot \"metrics.csv\" using \"step\":\"eval_return\" with linespoints pt 5 lw 2 title \"return\"\n"
       "set title \"evaluation success and episode length\"\n"
       "set ytics nomirror\n"
       "set y2tics\n"
       "set y2range [0:1]\n"
       "plot \"metrics.csv\" using \"step\":\"eval_length\" with linespoints pt 7 title \"length\", \\\n"
       "     \"\" using \"step\":(column(\"eval_success\") < 0 ? NaN : column(\"eval_success\")) with linespoints axes x1y2 pt 5 title \"success\"\n"
       "unset y2tics\n"
       "set ytics mirror\n"
       "set title \"losses\"\n"
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
       "unset multiplot\n"
       "set output\n"
       "system(\"mv -f learning_curve.png.tmp learning_curve.png\")\n";
  return g.str();
}

}  // namespace masa::offline
