#include "learner/run_dir/metrics_csv.hpp"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

namespace masa::learner {

namespace fs = std::filesystem;

namespace {

constexpr const char* kOldHeaderStart = "epoch,version,";  // metrics.csv before issue #32

// The update number a row starts with; false for the header or a torn row.
bool rowUpdate(const std::string& line, int64_t& update) {
  const std::size_t comma = line.find(',');
  if (comma == std::string::npos || comma == 0) return false;
  const auto [end, ec] = std::from_chars(line.data(), line.data() + comma, update);
  return ec == std::errc() && end == line.data() + comma;
}

}  // namespace

int64_t truncateMetricsCsv(const std::string& path, int64_t updates) {
  std::ifstream in(path);
  if (!in) return 0;
  std::vector<std::string> kept;
  int64_t removed = 0;
  std::string line;
  bool first = true;
  bool old_form = false;
  std::ptrdiff_t columns = -1;  // commas in the header: a row with fewer was torn
  while (std::getline(in, line)) {
    if (first && line.rfind(kOldHeaderStart, 0) == 0) old_form = true;
    if (old_form) {  // drop the first column (epoch): the second (version) is the update
      const std::size_t comma = line.find(',');
      line = comma == std::string::npos ? std::string() : line.substr(comma + 1);
      if (first) line.replace(0, std::string("version").size(), "update");
    }
    int64_t update = 0;
    const bool is_row = rowUpdate(line, update);
    const std::ptrdiff_t commas = std::count(line.begin(), line.end(), ',');
    if (first && !is_row) columns = commas;
    if ((first && !is_row) || (is_row && update <= updates && (columns < 0 || commas == columns))) {
      kept.push_back(line);
    } else {
      ++removed;
    }
    first = false;
  }
  in.close();
  if (removed == 0 && !old_form) return 0;
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    for (const std::string& l : kept) out << l << '\n';
    if (!out.flush()) throw std::runtime_error("resume: cannot rewrite " + tmp);
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) throw std::runtime_error("resume: cannot replace " + path + ": " + ec.message());
  return removed;
}

}  // namespace masa::learner
