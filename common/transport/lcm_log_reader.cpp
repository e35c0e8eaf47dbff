#include "common/transport/lcm_log_reader.hpp"

#include <stdexcept>

namespace masa::transport {
namespace {

constexpr uint32_t kSyncWord = 0xEDA1DA01u;
constexpr int kHeaderBytes = 4 + 8 + 8 + 4 + 4;
constexpr int32_t kMaxChannelBytes = 255;

uint64_t bigEndian(const uint8_t* p, int n) {
  uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

LcmLogReader::LcmLogReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
  if (!in_) throw std::runtime_error(path + ": cannot open the log");
  in_.seekg(0, std::ios::end);
  size_ = static_cast<int64_t>(in_.tellg());
  in_.seekg(0, std::ios::beg);
}

LcmLogReader::Result LcmLogReader::damaged(const std::string& why) {
  if (error_.empty()) error_ = path_ + ": not an LCM log at event " + std::to_string(events_ + 1) + ": " + why;
  return Result::kDamaged;
}

LcmLogReader::Result LcmLogReader::next(LogEvent& event) {
  if (!error_.empty()) return Result::kDamaged;
  const int64_t at = static_cast<int64_t>(in_.tellg());
  if (at < 0 || at >= size_) return Result::kEnd;
  if (size_ - at < kHeaderBytes) return Result::kEnd;  // a header cut short: the logger stopped there
  uint8_t h[kHeaderBytes];
  if (!in_.read(reinterpret_cast<char*>(h), kHeaderBytes)) return damaged("the header cannot be read");
  if (bigEndian(h, 4) != kSyncWord) return damaged("no sync word at byte " + std::to_string(at));
  const auto channel_len = static_cast<int32_t>(bigEndian(h + 20, 4));
  const auto data_len = static_cast<int32_t>(bigEndian(h + 24, 4));
  if (channel_len < 1 || channel_len > kMaxChannelBytes)
    return damaged("a channel name of " + std::to_string(channel_len) + " bytes (1-" + std::to_string(kMaxChannelBytes) + ")");
  if (data_len < 0) return damaged("a negative data length " + std::to_string(data_len));
  const int64_t left = size_ - at - kHeaderBytes;
  if (static_cast<int64_t>(channel_len) + data_len > left) return Result::kEnd;  // the last event, cut short
  event.number = static_cast<int64_t>(bigEndian(h + 4, 8));
  event.time_us = static_cast<int64_t>(bigEndian(h + 12, 8));
  event.channel.resize(static_cast<std::size_t>(channel_len));
  event.data.resize(static_cast<std::size_t>(data_len));
  if (!in_.read(event.channel.data(), channel_len) ||
      !in_.read(reinterpret_cast<char*>(event.data.data()), data_len))
    return damaged("the event cannot be read");
  if (event.channel.find('\0') != std::string::npos) return damaged("a channel name with a NUL byte");
  ++events_;
  return Result::kEvent;
}

}  // namespace masa::transport
