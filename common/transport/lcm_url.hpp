// LCM provider URLs for masa, and the kernel receive-buffer check that decides whether large
// messages survive on udpm.
//
// Without a large receive buffer most large multicast messages are lost; LCM asks for
// recv_buf_size, but the kernel silently caps it at net.core.rmem_max (4 MiB by default on
// Debian 12; raising it needs root: sysctl -w net.core.rmem_max=8388608).
#pragma once

#include <cstdint>
#include <string>

namespace masa::transport {

inline constexpr const char* kMulticastGroup = "239.255.76.67";  // LCM's default group and port
inline constexpr int kMulticastPort = 7667;
inline constexpr int64_t kDefaultRecvBufBytes = 8388608;  // 8 MiB

struct UdpmOptions {
  std::string group = kMulticastGroup;
  int port = kMulticastPort;
  int ttl = 0;  // 0: this host only; 1: one LAN segment
  int64_t recv_buf_size = kDefaultRecvBufBytes;
};

std::string udpmUrl(const UdpmOptions& options);
// udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608 : processes on this machine.
std::string loopbackUrl(int64_t recv_buf_size = kDefaultRecvBufBytes);
// The same with ttl=1: actors on other hosts of the LAN.
std::string lanUrl(int64_t recv_buf_size = kDefaultRecvBufBytes);

// The recv_buf_size a URL asks for; -1 when it names none (or is not udpm).
int64_t recvBufSizeOf(const std::string& url);

struct RecvBufCheck {
  int64_t requested = 0;
  int64_t rmem_max = -1;  // -1: could not be read
  bool sufficient = true;  // the kernel grants what was requested (or we cannot tell)
  std::string message;     // the warning, empty when sufficient
};
// Compares a requested receive buffer with rmem_max (read from `rmem_max_path`).
RecvBufCheck checkRecvBuf(int64_t requested, const std::string& rmem_max_path = "/proc/sys/net/core/rmem_max");

}  // namespace masa::transport

namespace masa::transport {

// The URL learner rank `rank` of `ranks` takes its actors' rollouts on (learner and actors both
// ask this one function): LCM delivers every channel of a multicast group and port to every socket
// subscribed there, so with several ranks each rank's share needs its own. One rank: `url` itself;
// several: udpm://G:P?opts -> udpm://G:(P + 1 + rank)?opts (the parameters stay on P, which every
// actor hears). Throws std::invalid_argument for other providers with several ranks (a tcpq hub
// relays everything to everyone: give each rank its own hub instead).
std::string rankRolloutUrl(const std::string& url, int rank, int ranks);

}  // namespace masa::transport
