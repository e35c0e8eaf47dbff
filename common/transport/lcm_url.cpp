#include "common/transport/lcm_url.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace masa::transport {

std::string udpmUrl(const UdpmOptions& o) {
  std::ostringstream os;
  os << "udpm://" << o.group << ":" << o.port << "?ttl=" << o.ttl;
  if (o.recv_buf_size > 0) os << "&recv_buf_size=" << o.recv_buf_size;
  return os.str();
}

std::string loopbackUrl(int64_t recv_buf_size) {
  UdpmOptions o;
  o.recv_buf_size = recv_buf_size;
  return udpmUrl(o);
}

std::string lanUrl(int64_t recv_buf_size) {
  UdpmOptions o;
  o.ttl = 1;
  o.recv_buf_size = recv_buf_size;
  return udpmUrl(o);
}

int64_t recvBufSizeOf(const std::string& url) {
  if (url.rfind("udpm://", 0) != 0) return -1;
  const std::string key = "recv_buf_size=";
  const std::size_t q = url.find('?');
  if (q == std::string::npos) return -1;
  std::size_t pos = q + 1;
  while (pos < url.size()) {
    const std::size_t end = std::min(url.find('&', pos), url.size());
    if (url.compare(pos, key.size(), key) == 0) {
      try {
        return std::stoll(url.substr(pos + key.size(), end - pos - key.size()));
      } catch (const std::exception&) {
        return -1;
      }
    }
    pos = end + 1;
  }
  return -1;
}

RecvBufCheck checkRecvBuf(int64_t requested, const std::string& rmem_max_path) {
  RecvBufCheck c;
  c.requested = requested;
  std::ifstream in(rmem_max_path);
  if (!(in >> c.rmem_max)) {
    c.rmem_max = -1;
    return c;
  }
  if (c.rmem_max < requested) {
    c.sufficient = false;
    std::ostringstream os;
    os << "LCM asks for a " << requested << "-byte receive buffer but net.core.rmem_max is " << c.rmem_max
       << ": the kernel grants at most that, and large messages may be lost under load. Raise it (as root): "
       << "sysctl -w net.core.rmem_max=" << requested;
    c.message = os.str();
  }
  return c;
}

}  // namespace masa::transport

namespace masa::transport {

std::string rankRolloutUrl(const std::string& url, int rank, int ranks) {
  if (ranks == 1) return url;
  const std::string scheme = "udpm://";
  if (url.rfind(scheme, 0) != 0)
    throw std::invalid_argument("data-parallel learner ranks need a udpm:// URL for their own rollout channels, got '" +
                                url + "'");
  const std::size_t colon = url.find(':', scheme.size());
  const std::size_t end = url.find('?', scheme.size());
  if (colon == std::string::npos || (end != std::string::npos && colon > end))
    throw std::invalid_argument("'" + url + "' names no port (udpm://GROUP:PORT)");
  const std::string port_text = url.substr(colon + 1, end == std::string::npos ? std::string::npos : end - colon - 1);
  int port = 0;
  try {
    std::size_t used = 0;
    port = std::stoi(port_text, &used);
    if (used != port_text.size()) throw std::invalid_argument("trailing characters");
  } catch (const std::exception&) {
    throw std::invalid_argument("'" + url + "' has no numeric port");
  }
  const int rank_port = port + 1 + rank;
  if (rank < 0 || rank >= ranks || port <= 0 || rank_port > 65535)
    throw std::invalid_argument("'" + url + "': no port " + std::to_string(rank_port) + " for rank " + std::to_string(rank));
  return url.substr(0, colon + 1) + std::to_string(rank_port) + (end == std::string::npos ? "" : url.substr(end));
}

}  // namespace masa::transport
