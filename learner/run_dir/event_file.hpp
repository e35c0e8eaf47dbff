// TensorBoard's event file, written by hand (no TensorFlow, no protobuf library): what
// `tensorboard --logdir runs` reads. A file is a sequence of records
//   uint64 length | uint32 masked CRC-32C of the length | the Event message | uint32 masked CRC-32C of it
// (little-endian; masked = ((crc >> 15) | (crc << 17)) + 0xa282ead8), each record an Event protobuf
// (wall_time = 1, step = 2, file_version = 3, summary = 5) whose Summary holds Values (tag = 1,
// simple_value = 2, or a text tensor: metadata = 9 naming the "text" plugin, tensor = 8 of DT_STRING).
//
// The run's file is DIR/events.out.tfevents.masa, one per run directory, appended as the run goes
// (each record flushed whole, so a killed run leaves every finished record readable); a resumed
// run first cuts it back to the checkpoint's step, as metrics.csv is cut, so no step repeats.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace masa::learner {

class EventFile {
 public:
  static constexpr const char* kFileName = "events.out.tfevents.masa";

  // Opens (creates) dir's event file for appending; a new file starts with its version record.
  explicit EventFile(const std::string& dir);
  ~EventFile();
  EventFile(const EventFile&) = delete;
  EventFile& operator=(const EventFile&) = delete;

  // wall_time: seconds since the epoch (0: now).
  void scalar(const std::string& tag, int64_t step, double value, double wall_time = 0);
  void text(const std::string& tag, int64_t step, const std::string& markdown, double wall_time = 0);
  const std::string& path() const { return path_; }

 private:
  void record(const std::string& event);

  std::string path_;
  std::FILE* file_ = nullptr;
};

// Text shown as it is (TensorBoard's text panel reads markdown: every line indented 4 spaces).
std::string preformatted(const std::string& text);

// One record read back.
struct EventRecord {
  double wall_time = 0;
  int64_t step = 0;
  std::string file_version;  // the first record's
  std::string tag;           // a summary value's
  bool is_scalar = false;
  float value = 0;
  std::string text;  // a text value's
};

struct EventFileContents {
  std::vector<EventRecord> records;
  std::vector<uint64_t> ends;  // the byte offset after each record
  bool torn_tail = false;      // the file ends inside a record (a run killed while writing it)
};

// Reads every record, checking both CRCs of each; throws std::runtime_error naming the offset of
// a record whose CRC does not match (a flipped byte) or that is not an event.
EventFileContents readEventFile(const std::string& path);

// Cuts the file after the last record of a step <= last_step (and any torn tail): what a resumed
// run does before it appends. Records of a step beyond are in step order, so the cut is one.
void truncateEventFile(const std::string& path, int64_t last_step);

}  // namespace masa::learner
