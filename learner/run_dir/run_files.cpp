#include "learner/run_dir/run_files.hpp"

#include <filesystem>
#include <stdexcept>

namespace masa::learner {
namespace fs = std::filesystem;

RunFiles::RunFiles(std::string dir, const std::string& config_text, long long step, Metrics metrics)
    : dir_(std::move(dir)) {
  fs::create_directories(dir_);
  std::ofstream config(path("config.yaml"));
  config << config_text;
  if (!config) throw std::runtime_error(path("config.yaml") + ": cannot write");
  events_ = std::make_unique<EventFile>(dir_);
  events_->text("config", step, preformatted(config_text));
  csv_events_ = std::make_unique<CsvEvents>(*events_, path("metrics.csv"), metrics.step, metrics.group);
}

std::string RunFiles::path(const std::string& name) const { return (fs::path(dir_) / name).string(); }

void RunFiles::startMetrics(const std::vector<std::string>& header) {
  csv_.open(path("metrics.csv"));
  if (!csv_) throw std::runtime_error(path("metrics.csv") + ": cannot write");
  for (size_t i = 0; i < header.size(); ++i) csv_ << (i ? "," : "") << header[i];
  csv_ << '\n';
  csv_.precision(7);
}

void RunFiles::continueMetrics() {
  csv_.open(path("metrics.csv"), std::ios::app);
  if (!csv_) throw std::runtime_error(path("metrics.csv") + ": cannot append");
  csv_.precision(7);
}

void RunFiles::endRow() {
  csv_.flush();
  if (!csv_) throw std::runtime_error(path("metrics.csv") + ": cannot write");
  csv_events_->mirrorLastRow();
}

}  // namespace masa::learner
