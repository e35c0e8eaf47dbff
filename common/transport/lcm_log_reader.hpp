// Reads the event log that lcm-logger writes (LCM's log format: per event a sync word 0xEDA1DA01,
// the event number and the receive time in microseconds as big-endian int64, the channel's and the
// data's lengths as big-endian int32, then the channel name and the data). A log is a file a user
// was handed, so every length is checked against the file before anything is read or allocated:
// a channel of 1-255 bytes, data no longer than what is left of the file. LCM's own reader trusts
// the data length and allocates it.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace masa::transport {

struct LogEvent {
  int64_t number = 0;
  int64_t time_us = 0;  // when lcm-logger received it
  std::string channel;
  std::vector<uint8_t> data;
};

class LcmLogReader {
 public:
  // Throws std::runtime_error naming the path when it cannot be opened.
  explicit LcmLogReader(const std::string& path);

  enum class Result { kEvent, kEnd, kDamaged };
  // The next event into `event`; kEnd at the end of the file (also after a partial last event that
  // lcm-logger was writing when it stopped, as LCM's reader treats it), kDamaged with error() set
  // when the bytes are not a log event (and every later call returns kDamaged).
  Result next(LogEvent& event);

  const std::string& error() const { return error_; }
  int64_t events() const { return events_; }  // events read so far

 private:
  Result damaged(const std::string& why);

  std::string path_;
  std::ifstream in_;
  int64_t size_ = 0;
  int64_t events_ = 0;
  std::string error_;
};

}  // namespace masa::transport
