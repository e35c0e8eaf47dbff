// Offline datasets as LCM logs: the file format of lcm-logger (and lcm-logplayer, lcm-spy), with
// the episodes on channel MASA_DATASET as lcmt_transitions messages, and seals on
// MASA_DATASET_SEAL that prove them intact (log_seal.hpp).
//
// The reader parses the log format itself rather than through liblcm's reader, which resyncs
// silently over damage and cannot tell a truncated last event from the end of the file. Every
// event is treated as hostile: the wire guard before decoding, checkTransitions() after, and the
// episode's messages must arrive in step order with nothing missing. What is refused is counted
// and reported; nothing of it enters the dataset.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/dataset/episode_record.hpp"
#include "common/dataset/log_seal.hpp"
#include "common/dataset/transition_dataset.hpp"

namespace lcm {
class LogFile;
}

namespace masa::dataset {

// Writes episodes into a new LCM log (as lcm-logger would have recorded them), each episode
// followed by a seal; not renamed into place, so that a long recording keeps what it sealed.
class DatasetLogWriter {
 public:
  // Throws when the file cannot be created.
  explicit DatasetLogWriter(const std::string& path, int max_steps_per_message = 256);
  ~DatasetLogWriter();
  void write(const EpisodeRecord& episode);
  int64_t episodesWritten() const { return episodes_; }

 private:
  void writeEvent(const char* channel, const unsigned char* data, int32_t size, int64_t utime);
  void writeSeal();

  std::string path_;
  int max_steps_;
  std::unique_ptr<lcm::LogFile> log_;
  LogSealChain seals_;
  int64_t episodes_ = 0;
};

struct LogReadReport {
  int files = 0;
  int64_t events = 0;              // events in the logs, every channel
  int64_t other_channel = 0;       // events on other channels (ignored)
  int64_t messages = 0;            // MASA_DATASET messages accepted
  int64_t episodes = 0;            // complete episodes in the dataset
  int64_t transitions = 0;
  int unsealed_files = 0;          // logs without any seal (read with a warning)
  std::map<std::string, int64_t> rejected;  // reason -> count (messages, or episodes where said)
  std::vector<std::string> notes;           // one line per damaged file, skipped episode kind, ...

  int64_t rejectedTotal() const;
  std::string summary() const;  // a few lines for a terminal
};

// Reads one or more logs into one dataset (episodes in file order). Throws std::runtime_error for a
// file that cannot be opened or is not an LCM log, for logs of different tasks or dimensions, and
// when no complete episode is found. A truncated or damaged tail is reported and skipped.
TransitionDataset readDatasetLogs(const std::vector<std::string>& paths, LogReadReport* report = nullptr);

// Every episode of a dataset as records (for subsets and re-recording): the inverse of the reader.
std::vector<EpisodeRecord> datasetEpisodes(const TransitionDataset& d);

}  // namespace masa::dataset
