#include "learner/run_dir/csv_events.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace masa::learner {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string cell; std::getline(s, cell, ',');) out.push_back(cell);
  return out;
}

bool startsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

// The file's last line (without its newline), read from the end.
std::string lastLine(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error(path + ": cannot read");
  const std::streamoff size = in.tellg();
  const std::streamoff span = std::min<std::streamoff>(size, 1 << 16);
  std::string tail(static_cast<std::size_t>(span), '\0');
  in.seekg(size - span);
  in.read(tail.data(), span);
  while (!tail.empty() && (tail.back() == '\n' || tail.back() == '\r')) tail.pop_back();
  const std::size_t nl = tail.rfind('\n');
  return nl == std::string::npos ? tail : tail.substr(nl + 1);
}

}  // namespace

std::string eventTag(const std::string& group, const std::string& column) {
  static const std::set<std::string> perf = {"fps", "env_steps_per_s", "steps_per_s", "wall_time_s", "wall_s"};
  static const std::set<std::string> transport = {"dropped_chunks", "dropped_envs", "policy_lag_mean", "policy_lag_max"};
  static const std::set<std::string> train = {"return", "length", "success", "episodes"};
  if (column == "update" || column == "updates") return "progress/" + column;
  if (startsWith(column, "eval_")) return "eval/" + column.substr(5);
  if (startsWith(column, "term_")) return "reward_terms/" + column.substr(5);
  if (startsWith(column, "train_")) return "train/" + column.substr(6);
  if (perf.count(column)) return "perf/" + column;
  if (transport.count(column)) return "transport/" + column;
  if (train.count(column)) return "train/" + column;
  return group + "/" + column;
}

CsvEvents::CsvEvents(EventFile& events, std::string csv_path, std::string step_column, std::string group,
                     std::vector<std::string> skip)
    : events_(events),
      csv_path_(std::move(csv_path)),
      step_column_(std::move(step_column)),
      group_(std::move(group)),
      skip_(std::move(skip)) {}

void CsvEvents::mirrorLastRow() {
  if (header_.empty()) {
    std::ifstream in(csv_path_);
    std::string line;
    if (!std::getline(in, line)) throw std::runtime_error(csv_path_ + ": no header to mirror into TensorBoard");
    header_ = split(line);
    const auto it = std::find(header_.begin(), header_.end(), step_column_);
    if (it == header_.end()) throw std::runtime_error(csv_path_ + ": no column " + step_column_);
    step_at_ = static_cast<int>(it - header_.begin());
  }
  const std::vector<std::string> row = split(lastLine(csv_path_));
  if (row.size() != header_.size()) return;  // the header itself, or a row of another shape: nothing to say
  const int64_t step = std::strtoll(row[step_at_].c_str(), nullptr, 10);
  for (std::size_t k = 0; k < row.size(); ++k) {
    if (static_cast<int>(k) == step_at_ || std::find(skip_.begin(), skip_.end(), header_[k]) != skip_.end()) continue;
    char* end = nullptr;
    const double v = std::strtod(row[k].c_str(), &end);
    if (end == row[k].c_str() || !std::isfinite(v)) continue;  // nan: nothing measured this row
    if (header_[k] == "success" && v < 0) continue;             // -1: a task without a success measure
    events_.scalar(eventTag(group_, header_[k]), step, v);
  }
}

}  // namespace masa::learner
