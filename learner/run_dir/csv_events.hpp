// A run's CSV rows as TensorBoard scalars: each row appended to metrics.csv (or off_policy.csv, or
// masa_sac's and the offline learners' metrics) is read back and every finite value of it written
// to the run's event file at the row's environment step, under a tag grouped by what the column is
// (train/, eval/, reward_terms/, learn/, perf/, transport/ ...). Reading the row back from the file
// makes the events exactly what the CSV says, for every writer, with one piece of code.
#pragma once

#include <string>
#include <vector>

#include "learner/run_dir/event_file.hpp"

namespace masa::learner {

// The tag of a CSV column: `group` is the file's own group for columns no rule names.
std::string eventTag(const std::string& group, const std::string& column);

class CsvEvents {
 public:
  // `skip`: columns another file of the run already gives (off_policy.csv's update).
  CsvEvents(EventFile& events, std::string csv_path, std::string step_column, std::string group,
            std::vector<std::string> skip = {});
  // Writes the CSV's last row (its header read once).
  void mirrorLastRow();

 private:
  EventFile& events_;
  std::string csv_path_, step_column_, group_;
  std::vector<std::string> skip_, header_;
  int step_at_ = -1;
};

}  // namespace masa::learner
