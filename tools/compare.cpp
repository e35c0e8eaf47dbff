// masa_compare: the paper's comparison from a grid of runs (experiments/grid.sh): per task, the
// median and 25-75% band over seeds of each method's training return, evaluation return and the
// task's progress figure against env steps, the training return against wall-clock time, and a
// verdict of the reference method (MASA) against each baseline with bootstrap intervals over seeds.
//   masa_compare experiments/results/a1_beam_grid            (DIR/<task>/<method>_s<seed>/metrics.csv or .csv.xz)
//   masa_compare DIR --reference masa --resamples 10000 --no-plot
//   masa_compare DIR --milestone eval_distance_m=5     (when each run's evaluation first walks 5 m)
//   masa_compare DIR --milestone 'eval_position_error_m<=0.05'   (a figure that falls: the cube first within 5 cm)
// Writes DIR/<task>/curves/<metric>_<method>.dat (env_steps wall_s median q25 q75 n), curves.csv
// (the same, one table), runs.csv (one row per run), compare.gp and compare.png; DIR/verdict.md,
// DIR/compare_all.gp and DIR/compare_all.png (every task on one page). `gnuplot compare.gp` in
// a task's folder redraws its figure from the .dat files.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <regex>
#include <sstream>

#include "common/core/build_info.hpp"
#include "common/core/shell_quoted.hpp"
#include "common/core/summary_stats.hpp"

using namespace masa;
namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kSmoothUpdates = 5;  // trailing mean of the training return, as the learning curves
constexpr int kFinalUpdates = 10;  // the final training return: mean of the last 10 updates

// One run's metrics.csv.
struct Run {
  std::string method;
  int seed = 0;
  bool done = false;
  std::map<std::string, std::vector<double>> columns;
  size_t rows() const { return columns.count("update") ? columns.at("update").size() : 0; }
  const std::vector<double>& col(const std::string& name) const {
    static const std::vector<double> empty;
    auto it = columns.find(name);
    return it == columns.end() ? empty : it->second;
  }
};

// A run's metrics: metrics.csv, or metrics.csv.xz as recorded grids keep them (experiments/README.md,
// the tree's budget), read through xz.
fs::path metricsFile(const fs::path& run_dir) {
  const fs::path plain = run_dir / "metrics.csv", packed = run_dir / "metrics.csv.xz";
  return fs::exists(plain) || !fs::exists(packed) ? plain : packed;
}

std::string decompressed(const fs::path& xz) {
  FILE* p = ::popen(("xz -dc -- " + shellQuoted(xz.string())).c_str(), "r");
  if (!p) throw std::runtime_error(xz.string() + ": cannot start xz to read it");
  std::string text;
  char buf[65536];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) text.append(buf, n);
  if (::pclose(p) != 0) throw std::runtime_error(xz.string() + ": xz could not read it (is xz-utils installed, is the file whole?)");
  return text;
}

Run readRun(const fs::path& csv) {
  std::ifstream file;
  std::istringstream unpacked;
  std::istream* source = &file;
  if (csv.extension() == ".xz") {
    unpacked.str(decompressed(csv));
    source = &unpacked;
  } else {
    file.open(csv);
  }
  std::istream& in = *source;
  if (!in) throw std::runtime_error(csv.string() + ": cannot read");
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(csv.string() + ": empty (no header)");
  std::vector<std::string> names;
  {
    std::stringstream ss(line);
    std::string name;
    while (std::getline(ss, name, ',')) names.push_back(name);
  }
  Run run;
  for (const auto& n : names) run.columns[n];
  // A run recorded before the update had one name counts epochs from 0 beside version = epoch + 1:
  // its `version` column is the update.
  const bool old_form = names.size() >= 2 && names[0] == "epoch" && names[1] == "version";
  if (old_form) {
    names[1] = "update";
    run.columns.erase("version");
    run.columns["update"];
  }
  for (const char* need : {"update", "env_steps", "wall_time_s", "return"})
    if (!run.columns.count(need)) throw std::runtime_error(csv.string() + ": no column '" + need + "'");
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    std::stringstream ss(line);
    std::string cell;
    size_t i = 0;
    std::vector<double> values;
    size_t bad = std::string::npos;  // the first cell that is not a number ("nan" and "inf" are)
    std::string bad_cell;
    while (std::getline(ss, cell, ',')) {
      char* end = nullptr;
      values.push_back(std::strtod(cell.c_str(), &end));
      if (bad == std::string::npos && (cell.empty() || end != cell.c_str() + cell.size()))
        bad = values.size() - 1, bad_cell = cell;
    }
    // A row cut short by a crash is the end of the run's record; a damaged cell anywhere else would
    // read as 0 and move medians and verdicts without a word.
    const bool last_row = in.peek() == std::char_traits<char>::eof();
    if (values.size() != names.size() || (bad != std::string::npos && last_row)) break;
    if (bad != std::string::npos)
      throw std::runtime_error(csv.string() + ":" + std::to_string(line_no) + ": column '" + names[bad] + "' holds '" +
                               bad_cell + "', not a number");
    for (i = 0; i < names.size(); ++i) run.columns[names[i]].push_back(values[i]);
  }
  return run;
}

// Methods in the grid's own order (grid.txt), else the reference first and the rest by name.
std::vector<std::string> methodOrder(const fs::path& dir, const std::vector<std::string>& found,
                                     const std::string& reference) {
  std::vector<std::string> order;
  std::ifstream grid(dir / "grid.txt");
  std::string line;
  while (std::getline(grid, line)) {
    if (line.rfind("methods=", 0) != 0) continue;
    std::stringstream ss(line.substr(8));
    std::string m;
    while (ss >> m)
      if (std::find(found.begin(), found.end(), m) != found.end()) order.push_back(m);
  }
  std::vector<std::string> rest = found;
  std::sort(rest.begin(), rest.end());
  if (std::find(rest.begin(), rest.end(), reference) != rest.end() &&
      std::find(order.begin(), order.end(), reference) == order.end())
    order.insert(order.begin(), reference);
  for (const auto& m : rest)
    if (std::find(order.begin(), order.end(), m) == order.end()) order.push_back(m);
  return order;
}

// A curve metric: a metrics.csv column, drawn where it has values.
struct Metric {
  std::string column;
  std::string label;
  bool smooth = false;
};

// Median and quartiles over runs at each update that every run reached with a value.
struct Band {
  std::vector<double> steps, wall, median, q25, q75;
  std::vector<int> n;
};

Band bandOf(const std::vector<const Run*>& runs, const Metric& m) {
  Band band;
  if (runs.empty()) return band;
  std::vector<std::vector<double>> values;
  size_t rows = std::numeric_limits<size_t>::max();
  for (const Run* r : runs) {
    const auto& raw = r->col(m.column);
    values.push_back(m.smooth ? stats::trailingMean(raw, kSmoothUpdates) : raw);
    rows = std::min(rows, r->rows());
  }
  for (size_t k = 0; k < rows; ++k) {
    std::vector<double> v, w;
    for (size_t i = 0; i < runs.size(); ++i) {
      if (values[i].size() <= k || std::isnan(values[i][k])) break;
      v.push_back(values[i][k]);
      w.push_back(runs[i]->col("wall_time_s")[k]);
    }
    if (v.size() != runs.size()) continue;
    band.steps.push_back(runs[0]->col("env_steps")[k]);
    band.wall.push_back(stats::median(w));
    band.median.push_back(stats::median(v));
    band.q25.push_back(stats::quantile(v, 0.25));
    band.q75.push_back(stats::quantile(std::move(v), 0.75));
    band.n.push_back(static_cast<int>(runs.size()));
  }
  return band;
}

// The last finite value of a column at or before x_max (NaN if none).
double lastValue(const Run& r, const std::string& column, double x_max) {
  const auto& x = r.col("env_steps");
  const auto& y = r.col(column);
  double out = kNaN;
  for (size_t k = 0; k < y.size() && x[k] <= x_max; ++k)
    if (!std::isnan(y[k])) out = y[k];
  return out;
}

double finalReturn(const Run& r, double x_max) {
  const auto& x = r.col("env_steps");
  const auto& y = r.col("return");
  std::vector<double> last;
  for (size_t k = 0; k < y.size() && x[k] <= x_max; ++k)
    if (!std::isnan(y[k])) last.push_back(y[k]);
  if (last.size() > static_cast<size_t>(kFinalUpdates)) last.erase(last.begin(), last.end() - kFinalUpdates);
  return stats::mean(last);
}

std::string fmt(double v, int precision = 1) {
  if (std::isnan(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", precision, v);
  return buf;
}

// A level as written: 5, 0.25, 1e+06.
std::string shortest(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string millions(double steps) { return std::isnan(steps) ? "n/a" : fmt(steps / 1e6, 2) + "M"; }

// Env steps in millions from 100k up, else whole; "-" for none (not reached).
std::string steps(double v) {
  if (std::isnan(v)) return "-";
  return std::fabs(v) >= 1e5 ? millions(v) : fmt(v, 0);
}

std::string color(const std::string& method, size_t index) {
  static const std::map<std::string, std::string> fixed = {
      {"masa", "#d62728"}, {"sa", "#1f77b4"}, {"sasa", "#2ca02c"}, {"ma", "#9467bd"}, {"sasa_data", "#8c564b"}};
  static const char* others[] = {"#ff7f0e", "#17becf", "#7f7f7f", "#bcbd22"};
  auto it = fixed.find(method);
  return it != fixed.end() ? it->second : others[index % 4];
}

// Task and method names are written into gnuplot scripts inside quotes, where a quote, a backquote
// or an @ would let a directory's name run commands: only names that cannot do that are read.
constexpr const char* kPlotSafeRule =
    "task and method names are letters, digits and _ . + - only (they are written into gnuplot scripts)";
bool plotSafeName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '+' || c == '-';
  });
}

// gnuplot lines for one panel: each method's band and median from curves/<metric>_<method>.dat.
std::string panel(const std::string& prefix, const std::string& metric, const std::vector<std::string>& methods,
                  bool wall_clock, bool keys) {
  std::string x = wall_clock ? "($2/60)" : "($1/1e6)";
  std::string plot = "plot ";
  bool first = true;
  for (size_t i = 0; i < methods.size(); ++i) {
    const std::string file = prefix + "curves/" + metric + "_" + methods[i] + ".dat";
    const std::string c = color(methods[i], i);
    if (!first) plot += ", \\\n     ";
    first = false;
    plot += "'" + file + "' using " + x + ":4:5 with filledcurves lc rgb '" + c + "' notitle, '" + file +
            "' using " + x + ":3 with lines lw 2 lc rgb '" + c + "' " +
            (keys ? "title '" + methods[i] + "'" : "notitle");
  }
  return plot + "\n";
}

// A milestone, [TASK:]COLUMN=LEVEL (or >=): the env steps of the first row at which a run's COLUMN
// reaches LEVEL (an evaluation figure: when the policy mean first walks 5 m), in the tasks that
// have it; [TASK:]COLUMN<=LEVEL for a figure that falls (when the cube is first within 5 cm).
struct Milestone {
  std::string task;  // empty: every task with the column
  std::string column;
  double level = 0;
  bool at_most = false;  // COLUMN<=LEVEL: reached when the column falls to the level
  std::string text;
  bool from_grid = false;  // grid.txt's: one that fits no task is noted, not fatal (the runs stand)
  std::string unmatched;   // why it fits no task, if it does not
  bool matched = false;
};

Milestone parseMilestone(const std::string& text) {
  static const std::regex form("(?:([A-Za-z0-9_]+):)?([A-Za-z0-9_]+)(<=|>=|=)([-+0-9.eE]+)");
  std::smatch m;
  Milestone out;
  char* end = nullptr;
  if (std::regex_match(text, m, form)) {
    const std::string level = m[4];
    out.level = std::strtod(level.c_str(), &end);
    if (end == level.c_str() + level.size() && std::isfinite(out.level)) {
      out.task = m[1];
      out.column = m[2];
      out.at_most = m[3] == "<=";
      out.text = text;
      return out;
    }
  }
  throw std::runtime_error("milestone '" + text +
                           "': write [TASK:]COLUMN=LEVEL, e.g. eval_distance_m=5 (or COLUMN<=LEVEL for a figure "
                           "that falls, e.g. eval_position_error_m<=0.05)");
}

// The command line's milestones, then the grid's (grid.txt lines "milestone=...") not among them.
std::vector<Milestone> readMilestones(const fs::path& dir, const std::vector<std::string>& given) {
  std::vector<Milestone> out;
  for (const auto& t : given) out.push_back(parseMilestone(t));
  std::ifstream grid(dir / "grid.txt");
  std::string line;
  while (std::getline(grid, line)) {
    if (line.rfind("milestone=", 0) != 0) continue;
    const std::string text = line.substr(10);
    if (std::find(given.begin(), given.end(), text) != given.end()) continue;
    try {
      out.push_back(parseMilestone(text));
    } catch (const std::exception& e) {
      throw std::runtime_error((dir / "grid.txt").string() + ": " + e.what());
    }
    out.back().from_grid = true;
  }
  return out;
}

struct TaskResult {
  std::string task;
  std::vector<std::string> methods;
  std::vector<Metric> metrics;  // drawn against steps; metrics[0] is the training return
};

// One run's figures over the budget.
struct Summary {
  double auc, final_return, final_eval, wall;
};

// The verdict's table of the reference against each baseline: bootstrap intervals of the
// differences in mean return over the budget and in final evaluation return, when the reference
// reaches the baseline's final return, and the call.
void writeBaselines(std::ostream& verdict, const std::string& reference, const std::vector<std::string>& methods,
                    std::map<std::string, std::vector<Summary>>& summaries, const Band& rb, double budget,
                    int resamples) {
  verdict << "| baseline | " << reference << " - baseline: mean return over budget [95%] | " << reference
          << " - baseline: final eval return [95%] | " << reference
          << " reaches the baseline's final return at | verdict |\n|---|---|---|---|---|\n";
  for (const auto& base : methods) {
    if (base == reference) continue;
    auto pick = [&](const std::string& m, double Summary::*f) {
      std::vector<double> v;
      for (const auto& s : summaries[m])
        if (!std::isnan(s.*f)) v.push_back(s.*f);
      return v;
    };
    Rng rng(12345);
    const auto a_auc = pick(reference, &Summary::auc), b_auc = pick(base, &Summary::auc);
    const auto a_ev = pick(reference, &Summary::final_eval), b_ev = pick(base, &Summary::final_eval);
    if (a_auc.empty() || b_auc.empty()) {  // no episode ended within the budget
      verdict << "| " << base << " | n/a | n/a | n/a | no finished episodes to compare |\n";
      continue;
    }
    const auto auc = stats::bootstrapMeanDifference(a_auc, b_auc, resamples, 0.95, rng);
    std::string ev_text = "n/a";
    stats::Interval ev{kNaN, kNaN, kNaN};
    if (!a_ev.empty() && !b_ev.empty()) {
      ev = stats::bootstrapMeanDifference(a_ev, b_ev, resamples, 0.95, rng);
      ev_text = fmt(ev.estimate) + " [" + fmt(ev.low) + ", " + fmt(ev.high) + "]";
    }
    const double level = stats::median(pick(base, &Summary::final_return));
    const double reach = stats::firstCrossing(rb.steps, rb.median, level);
    std::string reach_text = std::isnan(reach) ? "not within the budget (" + fmt(level) + ")"
                                               : millions(reach) + " (" + fmt(100.0 * reach / budget, 0) +
                                                     "% of the budget; level " + fmt(level) + ")";
    const size_t n = std::min(a_auc.size(), b_auc.size());
    std::string call;
    auto side = [&](const stats::Interval& iv) {
      return iv.low > 0 ? 1 : iv.high < 0 ? -1 : 0;
    };
    if (n < 3) {
      call = "too few seeds (" + std::to_string(n) + ") to tell";
    } else {
      const int s_auc = side(auc), s_ev = std::isnan(ev.low) ? 0 : side(ev);
      if (s_auc > 0 && s_ev >= 0) call = reference + " ahead (learns faster" + (s_ev > 0 ? ", ends higher)" : ")");
      else if (s_auc < 0 && s_ev <= 0) call = base + " ahead (" + reference + "'s ordering does not hold)";
      else if (s_auc == 0 && s_ev == 0) call = "cannot tell at this budget";
      else if (s_auc == 0) call = (s_ev > 0 ? reference : base) + " ends higher; learning speed cannot be told apart";
      else call = "mixed: " + std::string(s_auc > 0 ? reference : base) + " learns faster, " +
                  (s_ev > 0 ? reference : base) + " ends higher";
    }
    verdict << "| " << base << " | " << fmt(auc.estimate) << " [" << fmt(auc.low) << ", " << fmt(auc.high)
            << "] | " << ev_text << " | " << reach_text << " | " << call << " |\n";
  }
  verdict << "\n";
}

// The verdict's table of one milestone for one task: the env steps at which each run first
// reaches the level; a run that never does counts as later than any that does.
void writeMilestone(std::ostream& verdict, Milestone& ms, const std::string& task, const Run& any,
                    const std::vector<std::string>& methods, const std::map<std::string, std::vector<const Run*>>& used,
                    double budget, const std::string& reference, int resamples) {
  if (!any.columns.count(ms.column)) {
    if (!ms.task.empty()) ms.unmatched = task + "'s metrics.csv has no column '" + ms.column + "'";
    return;
  }
  ms.matched = true;
  verdict << "Milestone " << ms.column << (ms.at_most ? " <= " : " >= ") << shortest(ms.level)
          << ": the env steps of the first row at which it holds (an evaluation figure is known only "
          << "at the evaluations); a seed that never reaches it within the budget counts as later than "
          << "any that does.\n\n| method | seeds that reach it | per seed | median | " << reference
          << " - method: steps [95%] |\n|---|---|---|---|---|\n";
  std::map<std::string, std::vector<double>> reached;  // NaN: not within the budget
  for (const auto& m : methods)
    for (const Run* r : used.at(m))
      reached[m].push_back(ms.at_most ? stats::firstFallenTo(r->col("env_steps"), r->col(ms.column), ms.level, budget)
                                      : stats::firstReached(r->col("env_steps"), r->col(ms.column), ms.level, budget));
  auto allReached = [](const std::vector<double>& v) {
    return std::none_of(v.begin(), v.end(), [](double x) { return std::isnan(x); });
  };
  for (const auto& m : methods) {
    const auto& v = reached[m];
    std::vector<double> sorted;  // a run that never reached it is beyond any that did
    std::string per_seed;
    int count = 0;
    for (size_t i = 0; i < v.size(); ++i) {
      count += !std::isnan(v[i]);
      sorted.push_back(std::isnan(v[i]) ? std::numeric_limits<double>::infinity() : v[i]);
      per_seed += (i ? ", s" : "s") + std::to_string(used.at(m)[i]->seed) + " " + steps(v[i]);
    }
    // The median by hand: interpolating towards "never" (infinity) would give NaN.
    std::sort(sorted.begin(), sorted.end());
    const size_t n = sorted.size();
    const double med = n == 0       ? std::numeric_limits<double>::infinity()
                       : n % 2 ? sorted[n / 2]
                               : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
    std::string diff;
    if (m != reference && reached.count(reference)) {
      const auto& a = reached[reference];
      if (allReached(a) && allReached(v) && !a.empty() && !v.empty()) {
        Rng rng(12345);
        const auto iv = stats::bootstrapMeanDifference(a, v, resamples, 0.95, rng);
        diff = steps(iv.estimate) + " [" + steps(iv.low) + ", " + steps(iv.high) + "]";
      } else {
        diff = "n/a (a seed never reached it)";
      }
    }
    verdict << "| " << m << " | " << count << " of " << v.size() << " | " << per_seed << " | "
            << (std::isinf(med) ? "not within the budget" : steps(med)) << " | " << diff << " |\n";
  }
  verdict << "\n";
}

// A task's figure (a gnuplot script): each metric against env steps, the training return against time.
void writeTaskFigure(const fs::path& path, const std::string& task, const std::vector<Metric>& metrics,
                     const std::vector<std::string>& methods, size_t most_seeds) {
  const size_t panels = metrics.size() + 1;
  const int cols = panels > 2 ? 2 : static_cast<int>(panels);
  const int rows_ = static_cast<int>((panels + cols - 1) / cols);
  std::ofstream gp(path);
  gp << "# " << task << ": median and 25-75% band over seeds. Redraw here with: gnuplot compare.gp\n"
     << "set terminal pngcairo size " << 700 * cols << "," << 450 * rows_ << " font ',10'\n"
     << "set output 'compare.png.tmp'\nset termoption noenhanced\n"
     << "set style fill transparent solid 0.2 noborder\nset grid\nset key bottom right\n"
     << "set multiplot layout " << rows_ << "," << cols << " title '" << task << ": median and 25-75% over "
     << most_seeds << " seeds per method'\n";
  bool keys = true;
  for (const auto& metric : metrics) {
    gp << "set title '" << metric.label << "'\nset xlabel 'env steps (millions)'\n"
       << panel("", metric.column, methods, false, keys);
    keys = false;
  }
  gp << "set title 'training return against wall-clock time (one core per run)'\nset xlabel 'minutes'\n"
     << panel("", "return", methods, true, false);
  gp << "unset multiplot\nset output\nsystem('mv -f compare.png.tmp compare.png')\n";
  gp.close();
}

// One task of the grid: its curves, runs.csv, its section of the verdict (medians, each baseline
// against the reference, the milestones) and its figure's gnuplot script. Nothing when it has no runs.
std::optional<TaskResult> compareTask(const fs::path& dir, const std::string& task, const std::string& reference,
                                      int resamples, std::vector<Milestone>& milestones, std::ostream& verdict) {
  const std::regex run_name("(.+)_s([0-9]+)");
  std::map<std::string, std::vector<Run>> by_method;
  for (const auto& e : fs::directory_iterator(dir / task)) {
    std::smatch m;
    const std::string name = e.path().filename().string();
    if (!e.is_directory() || !std::regex_match(name, m, run_name)) continue;
    if (!plotSafeName(m[1])) {
      std::cerr << "masa_compare: skipped " << (dir / task / name).string() << ": " << kPlotSafeRule << "\n";
      continue;
    }
    const fs::path csv = metricsFile(e.path());
    if (!fs::exists(csv)) continue;
    Run run = readRun(csv);
    if (run.rows() < 2) continue;
    run.method = m[1];
    run.seed = std::stoi(m[2]);
    run.done = fs::exists(e.path() / "done");
    by_method[run.method].push_back(std::move(run));
  }
  if (by_method.empty()) return std::nullopt;
  std::vector<std::string> found;
  for (auto& [m, runs] : by_method) {
    found.push_back(m);
    std::sort(runs.begin(), runs.end(), [](const Run& a, const Run& b) { return a.seed < b.seed; });
  }
  const auto methods = methodOrder(dir, found, reference);

  // Finished runs only, once every method has one; until then every run, said so.
  bool all_done = true;
  for (const auto& [m, runs] : by_method)
    all_done = all_done && std::any_of(runs.begin(), runs.end(), [](const Run& r) { return r.done; });
  std::map<std::string, std::vector<const Run*>> used;
  double budget = std::numeric_limits<double>::infinity();
  for (const auto& [m, runs] : by_method)
    for (const auto& r : runs)
      if (r.done || !all_done) {
        used[m].push_back(&r);
        budget = std::min(budget, r.col("env_steps").back());
      }

  // The metrics: training return, evaluation return, the task's progress figures, success.
  const Run& any = *used.begin()->second.front();
  std::vector<Metric> metrics = {{"return", "training return (trailing mean of 5 updates)", true}};
  auto hasValues = [&](const std::string& c, double min) {
    for (const auto& [m, runs] : used)
      for (const Run* r : runs)
        for (double v : r->col(c))
          if (!std::isnan(v) && v >= min) return true;
    return false;
  };
  if (hasValues("eval_return", -1e300)) metrics.push_back({"eval_return", "evaluation return (policy mean)", false});
  for (const auto& [c, values] : any.columns)
    if (c.rfind("eval_", 0) == 0 && c != "eval_return" && c != "eval_length" && c != "eval_success" &&
        hasValues(c, -1e300))
      metrics.push_back({c, "evaluation " + c.substr(5), false});
  if (hasValues("eval_success", 0.0)) metrics.push_back({"eval_success", "evaluation success rate", false});

  fs::create_directories(dir / task / "curves");
  std::ofstream curves(dir / task / "curves.csv");
  curves << "method,metric,env_steps,wall_s,median,q25,q75,n\n";
  std::map<std::string, Band> return_band;
  for (const auto& metric : metrics) {
    for (const auto& m : methods) {
      const Band b = bandOf(used[m], metric);
      if (metric.column == "return") return_band[m] = b;
      std::ofstream dat(dir / task / "curves" / (metric.column + "_" + m + ".dat"));
      dat << "# " << task << " " << m << " " << metric.column << ": env_steps wall_s median q25 q75 n\n";
      for (size_t k = 0; k < b.steps.size(); ++k) {
        dat << b.steps[k] << ' ' << b.wall[k] << ' ' << b.median[k] << ' ' << b.q25[k] << ' ' << b.q75[k] << ' '
            << b.n[k] << '\n';
        curves << m << ',' << metric.column << ',' << b.steps[k] << ',' << b.wall[k] << ',' << b.median[k] << ','
               << b.q25[k] << ',' << b.q75[k] << ',' << b.n[k] << '\n';
      }
    }
  }

  // One row per run.
  std::map<std::string, std::vector<Summary>> summaries;
  std::ofstream runs_csv(dir / task / "runs.csv");
  runs_csv << "method,seed,done,updates,env_steps,wall_s,mean_return_over_budget,final_return,final_eval_return\n";
  for (const auto& m : methods)
    for (const Run* r : used[m]) {
      Summary s;
      s.auc = stats::meanUnderCurve(r->col("env_steps"), r->col("return"), budget);
      s.final_return = finalReturn(*r, budget);
      s.final_eval = lastValue(*r, "eval_return", budget);
      s.wall = r->col("wall_time_s").back();
      summaries[m].push_back(s);
      runs_csv << m << ',' << r->seed << ',' << (r->done ? 1 : 0) << ',' << r->rows() << ','
               << r->col("env_steps").back() << ',' << s.wall << ',' << s.auc << ',' << s.final_return << ','
               << s.final_eval << '\n';
    }

  // The verdict against each baseline.
  size_t most_seeds = 0;
  for (const auto& [m, runs] : used) most_seeds = std::max(most_seeds, runs.size());
  verdict << "## " << task << "\n\nBudget " << millions(budget) << " env steps per run"
          << (all_done ? "" : " (unfinished runs included: not every method has a finished run)") << ".\n\n";
  verdict << "| method | seeds | mean return over budget (median) | final return (median) | final eval return "
             "(median) | wall time (median) |\n|---|---|---|---|---|---|\n";
  for (const auto& m : methods) {
    std::vector<double> auc, fin, ev, wall;
    for (const auto& s : summaries[m]) {
      auc.push_back(s.auc);
      fin.push_back(s.final_return);
      if (!std::isnan(s.final_eval)) ev.push_back(s.final_eval);
      wall.push_back(s.wall);
    }
    verdict << "| " << m << " | " << used[m].size() << " | " << fmt(stats::median(auc)) << " | "
            << fmt(stats::median(fin)) << " | " << fmt(stats::median(ev)) << " | "
            << fmt(stats::median(wall) / 60.0) << " min |\n";
  }
  verdict << "\n";
  if (by_method.count(reference)) writeBaselines(verdict, reference, methods, summaries, return_band.at(reference), budget, resamples);

  for (auto& ms : milestones)
    if (ms.task.empty() || ms.task == task) writeMilestone(verdict, ms, task, any, methods, used, budget, reference, resamples);

  writeTaskFigure(dir / task / "compare.gp", task, metrics, methods, most_seeds);
  std::printf("masa_compare: %s: %zu methods, up to %zu seeds, budget %s steps -> %s\n", task.c_str(),
              methods.size(), most_seeds, millions(budget).c_str(), (dir / task / "compare.png").c_str());
  return TaskResult{task, methods, metrics};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"masa compare: figures and verdict of a grid of runs (experiments/grid.sh)"};
  app.set_version_flag("--version", masa::buildCommit());
  std::string dir_arg, reference = "masa";
  int resamples = 10000;
  bool no_plot = false;
  std::vector<std::string> milestone_texts;
  app.add_option("dir", dir_arg, "the grid's directory (DIR/<task>/<method>_s<seed>/metrics.csv)")->required();
  app.add_option("--reference", reference, "the method compared against every other");
  app.add_option("--resamples", resamples, "bootstrap resamples")->check(CLI::Range(100, 1000000));
  app.add_flag("--no-plot", no_plot, "write the tables and gnuplot scripts, do not run gnuplot");
  app.add_option("--milestone", milestone_texts,
                 "[TASK:]COLUMN=LEVEL: when each run's COLUMN first reaches LEVEL; COLUMN<=LEVEL: first falls "
                 "to it (repeatable; grid.txt lines milestone=... add theirs)");
  CLI11_PARSE(app, argc, argv);

  try {
    const fs::path dir = fs::absolute(dir_arg);
    if (!fs::is_directory(dir)) throw std::runtime_error(dir_arg + ": no such directory");
    std::vector<Milestone> milestones = readMilestones(dir, milestone_texts);
    std::vector<std::string> task_names;
    for (const auto& e : fs::directory_iterator(dir)) {
      if (!e.is_directory()) continue;
      const std::string name = e.path().filename().string();
      if (plotSafeName(name))
        task_names.push_back(name);
      else
        std::cerr << "masa_compare: skipped " << e.path().string() << ": " << kPlotSafeRule << "\n";
    }
    std::sort(task_names.begin(), task_names.end());

    std::ostringstream verdict;
    verdict << "# Comparison: " << reference << " against each baseline\n\n"
            << "Per task and baseline, over the seeds that finished: the difference (" << reference
            << " - baseline) of the mean training return over the whole budget (the area under the curve "
            << "divided by the steps) and of the final deterministic evaluation return, each with a "
            << "percentile bootstrap 95% interval over seeds (" << resamples << " resamples); and the env "
            << "steps at which " << reference << "'s median training return (trailing mean of "
            << kSmoothUpdates << " updates) first reaches the baseline's median final return (mean of the "
            << "last " << kFinalUpdates << " updates). An interval that excludes 0 is a difference; one "
            << "that includes it cannot tell at this budget.\n\n";
    std::vector<TaskResult> drawn;

    for (const auto& task : task_names)
      if (auto drawn_task = compareTask(dir, task, reference, resamples, milestones, verdict))
        drawn.push_back(std::move(*drawn_task));
    if (drawn.empty()) throw std::runtime_error(dir_arg + ": no runs (<task>/<method>_s<seed>/metrics.csv) found");
    for (auto& ms : milestones) {
      if (ms.matched) continue;
      if (ms.unmatched.empty())
        ms.unmatched = ms.task.empty() ? "no task's metrics.csv has the column '" + ms.column + "'"
                                       : "the grid has no task '" + ms.task + "' with runs";
      if (!ms.from_grid) throw std::runtime_error("milestone " + ms.text + ": " + ms.unmatched);
      std::fprintf(stderr, "masa_compare: warning: grid.txt's milestone %s: %s\n", ms.text.c_str(),
                   ms.unmatched.c_str());
      verdict << "Milestone " << ms.text << " (grid.txt): not measured, " << ms.unmatched << ".\n\n";
    }

    {
      std::ofstream v(dir / "verdict.md");
      v << verdict.str();
    }
    // Every task on one page: training return and evaluation return against steps, return against time.
    std::ofstream gp(dir / "compare_all.gp");
    gp << "# Every task of the grid. Redraw here with: gnuplot compare_all.gp\n"
       << "set terminal pngcairo size 2100," << 450 * drawn.size() << " font ',10'\n"
       << "set output 'compare_all.png.tmp'\nset termoption noenhanced\n"
       << "set style fill transparent solid 0.2 noborder\nset grid\nset key bottom right\n"
       << "set multiplot layout " << drawn.size() << ",3 title 'median and 25-75% over seeds'\n";
    for (const auto& t : drawn) {
      const std::string prefix = t.task + "/";
      gp << "set title '" << t.task << ": training return'\nset xlabel 'env steps (millions)'\n"
         << panel(prefix, "return", t.methods, false, true);
      if (t.metrics.size() > 1)
        gp << "set title '" << t.task << ": " << t.metrics[1].label << "'\n"
           << panel(prefix, t.metrics[1].column, t.methods, false, false);
      else
        gp << "set multiplot next\n";
      gp << "set title '" << t.task << ": training return'\nset xlabel 'minutes'\n"
         << panel(prefix, "return", t.methods, true, false);
    }
    gp << "unset multiplot\nset output\nsystem('mv -f compare_all.png.tmp compare_all.png')\n";
    gp.close();
    std::cout << verdict.str();

    if (!no_plot) {
      bool ok = true;
      for (const auto& t : drawn)
        ok = std::system(("cd " + shellQuoted((dir / t.task).string()) + " && gnuplot compare.gp").c_str()) == 0 && ok;
      ok = std::system(("cd " + shellQuoted(dir.string()) + " && gnuplot compare_all.gp").c_str()) == 0 && ok;
      if (!ok) throw std::runtime_error("gnuplot failed (is it installed? scripts/install_deps.sh installs gnuplot-nox)");
      std::printf("masa_compare: figures %s and %s/<task>/compare.png; verdict %s\n",
                  (dir / "compare_all.png").c_str(), dir.c_str(), (dir / "verdict.md").c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_compare: %s\n", e.what());
    return 2;
  }
  return 0;
}
