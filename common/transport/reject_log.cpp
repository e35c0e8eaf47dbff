#include "common/transport/reject_log.hpp"

#include <iostream>

namespace masa::transport {

void RejectLog::count(const std::string& channel, WireVerdict why, std::string_view hint) {
  ++total_;
  ChannelRejects& r = channels_[channel];
  ++r.count[static_cast<int>(why)];
  ++r.unwarned;
  constexpr auto kWarnInterval = std::chrono::seconds(5);
  const auto now = std::chrono::steady_clock::now();
  if (r.warned && now - r.last_warning < kWarnInterval) return;
  int64_t on_channel = 0;
  for (int64_t n : r.count) on_channel += n;
  std::cerr << "masa transport: rejected " << r.unwarned << " message(s) on " << channel << " (latest: "
            << wireVerdictName(why) << "); " << on_channel << " rejected on this channel so far";
  if (!hint.empty()) std::cerr << " (" << hint << ")";
  std::cerr << "\n";
  r.warned = true;
  r.last_warning = now;
  r.unwarned = 0;
}

WireRejects RejectLog::of(const std::string& channel) const {
  const auto it = channels_.find(channel);
  return it == channels_.end() ? WireRejects{} : it->second.count;
}

std::string RejectLog::summary() const {
  std::string out;
  for (const auto& [channel, r] : channels_) {
    std::string reasons;
    for (int v = 0; v < kNumWireVerdicts; ++v) {
      if (r.count[v] == 0) continue;
      if (!reasons.empty()) reasons += ", ";
      reasons += std::string(wireVerdictName(static_cast<WireVerdict>(v))) + " " + std::to_string(r.count[v]);
    }
    if (reasons.empty()) continue;
    if (!out.empty()) out += "; ";
    out += channel + ": " + reasons;
  }
  return out.empty() ? "none" : out;
}

}  // namespace masa::transport
