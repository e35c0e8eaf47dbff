// The MessageBus that replays a recorded log (lcm-logger's): each handle*() call hands the log's
// next event to the subscriptions whose channel pattern matches, in the log's order and without
// waiting, as Transport would hand over the bytes: raw subscribers get them as recorded (a signed
// run's trailer included), typed ones through the wire guard, its rejects counted. Nothing is
// verified: a log is as trusted as the file it came in. Read-only: publishing returns false.
// For tools that read recordings with the code that reads the network (masa_lcm_probe --log).
#pragma once

#include <cstdint>
#include <string>

#include "common/transport/lcm_log_reader.hpp"
#include "common/transport/local_bus.hpp"

namespace masa::transport {

class LogBus : public LocalBus {
 public:
  // Throws std::runtime_error naming the path when it cannot be opened.
  explicit LogBus(const std::string& path);

  bool publishRaw(const std::string& channel, const void* data, int size) override;
  // The next event: 1 dispatched, 0 the log has ended, -1 the log is damaged (error()). The timeout
  // is ignored: a log has no one to wait for.
  int handleTimeout(int timeout_ms) override;
  // Replays the rest of the log; returns how many events.
  int drain() override;

  bool ended() const { return ended_; }
  const std::string& error() const { return reader_.error(); }
  // The receive time (lcm-logger's clock, microseconds) of the event last dispatched.
  int64_t eventTimeUs() const { return event_.time_us; }
  int64_t events() const { return reader_.events(); }

 protected:
  bool publishMessage(const std::string& channel, const OutgoingMessage& msg) override;

 private:
  LcmLogReader reader_;
  LogEvent event_;
  bool ended_ = false;
};

}  // namespace masa::transport
