// The count of messages a transport rejected before their handler, per channel and reason, with a
// rate-limited warning on stderr: a fuzzer or a misconfigured peer must be visible, not fill the log.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>

#include "common/transport/wire_guard.hpp"

namespace masa::transport {

class RejectLog {
 public:
  // Counts one message rejected on `channel` for `why`; warns at most once per channel every few
  // seconds, the line ending with `hint` (what to check for this reason) when given.
  void count(const std::string& channel, WireVerdict why, std::string_view hint = {});

  int64_t total() const { return total_; }
  WireRejects of(const std::string& channel) const;
  // "MASA_POLICY: malformed 12, unauthenticated 3; ...", or "none".
  std::string summary() const;

 private:
  struct ChannelRejects {
    WireRejects count{};
    bool warned = false;
    std::chrono::steady_clock::time_point last_warning{};
    int64_t unwarned = 0;  // rejected since the last warning
  };
  std::map<std::string, ChannelRejects> channels_;
  int64_t total_ = 0;
};

}  // namespace masa::transport
