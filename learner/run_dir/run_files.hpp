// config.yaml, metrics.csv and the TensorBoard events of a run, opened the same way by every
// trainer (the distributed learner's PPO and off-policy runs, masa_sac, masa_offline): the
// resolved configuration written beside the data and as the events' text at the step the run
// (re)starts from, metrics.csv created with its header or, on resume, appended to, and each row
// appended mirrored into the event file (csv_events.hpp), so no writer has its own way of doing it.
#pragma once

#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "learner/run_dir/csv_events.hpp"
#include "learner/run_dir/event_file.hpp"

namespace masa::learner {

class RunFiles {
 public:
  // The columns of metrics.csv: `step` names the column events are placed at (env_step, step),
  // `group` the TensorBoard group of the columns no rule names.
  struct Metrics {
    std::string step;
    std::string group;
  };

  // Creates `dir`, writes config.yaml (config_text) and opens the event file with the config as
  // text at `step`. The caller has refused a directory in use (run_directory.hpp) and, on resume,
  // cut metrics.csv and the events back to its checkpoint.
  RunFiles(std::string dir, const std::string& config_text, long long step, Metrics metrics);

  // A fresh run: metrics.csv (re)written with `header`, open for rows. Throws naming the file.
  void startMetrics(const std::vector<std::string>& header);
  // A resumed run: metrics.csv open to append. Throws naming the file.
  void continueMetrics();
  // The open metrics.csv; a row is written to it and then endRow() called.
  std::ofstream& metrics() { return csv_; }
  // Flushes the row written and mirrors it into the events.
  void endRow();

  EventFile& events() { return *events_; }
  const std::string& dir() const { return dir_; }
  std::string path(const std::string& name) const;  // dir/name

 private:
  std::string dir_;
  std::ofstream csv_;
  std::unique_ptr<EventFile> events_;
  std::unique_ptr<CsvEvents> csv_events_;
};

}  // namespace masa::learner
