#include "common/transport/log_bus.hpp"

namespace masa::transport {

LogBus::LogBus(const std::string& path) : reader_(path) {}

bool LogBus::publishRaw(const std::string&, const void*, int) { return false; }
bool LogBus::publishMessage(const std::string&, const OutgoingMessage&) { return false; }

int LogBus::handleTimeout(int) {
  switch (reader_.next(event_)) {
    case LcmLogReader::Result::kEnd:
      ended_ = true;
      return 0;
    case LcmLogReader::Result::kDamaged:
      return -1;
    case LcmLogReader::Result::kEvent:
      break;
  }
  // Through the in-process bus's queue and dispatch: the same matching and guard as live messages.
  LocalBus::publishRaw(event_.channel, event_.data.data(), static_cast<int>(event_.data.size()));
  return LocalBus::handleTimeout(0);
}

int LogBus::drain() {
  int n = 0;
  while (handleTimeout(0) > 0) ++n;
  return n;
}

}  // namespace masa::transport
