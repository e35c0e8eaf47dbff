#include "common/transport/lcm_url.hpp"

#include <fstream>
#include <sstream>

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
