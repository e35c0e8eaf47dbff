#include "common/transport/run_key.hpp"

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include <fcntl.h>
#include <openssl/evp.h>
#include <openssl/rand.h>
#include <sys/stat.h>
#include <unistd.h>

namespace masa::transport {

namespace {

std::string toHex(const uint8_t* p, int n) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string s(static_cast<std::size_t>(2 * n), '0');
  for (int i = 0; i < n; ++i) {
    s[2 * i] = kDigits[p[i] >> 4];
    s[2 * i + 1] = kDigits[p[i] & 15];
  }
  return s;
}

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::runtime_error keyError(const std::string& path, const std::string& what) {
  return std::runtime_error("run key " + path + ": " + what);
}

void writeAll(int fd, const std::string& text, const std::string& path) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw keyError(path, std::string("cannot write: ") + std::strerror(errno));
    done += static_cast<std::size_t>(n);
  }
}

}  // namespace

RunKey RunKey::random() {
  RunKey k;
  if (RAND_bytes(k.bytes.data(), kBytes) != 1) throw std::runtime_error("run key: OpenSSL's RAND_bytes failed");
  return k;
}

std::string RunKey::id() const {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (EVP_Digest(bytes.data(), kBytes, digest, &n, EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("run key: SHA-256 failed");
  return toHex(digest, 4);
}

RunKey readRunKey(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw keyError(path, std::string("cannot read: ") + std::strerror(errno));
  std::ostringstream text;
  text << f.rdbuf();
  std::string s = text.str();
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  if (s.size() != 2 * RunKey::kBytes)
    throw keyError(path, "expected " + std::to_string(2 * RunKey::kBytes) + " hex digits, found " +
                             std::to_string(s.size()) + " characters (make one with deploy/run_key.sh)");
  RunKey k;
  for (int i = 0; i < RunKey::kBytes; ++i) {
    const int hi = hexValue(s[2 * i]), lo = hexValue(s[2 * i + 1]);
    if (hi < 0 || lo < 0) throw keyError(path, "not hex digits at character " + std::to_string(2 * i + 1));
    k.bytes[i] = static_cast<uint8_t>(hi << 4 | lo);
  }
  // Whoever reads the key can sign as the run: refuse a key others may read (as ssh refuses a
  // private key), as the Ed25519 private keys are.
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && (st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    throw keyError(path, std::string("has mode ") + mode + ": others may read it and forge this run's messages (chmod 600 " +
                             path + ")");
  }
  return k;
}

RunKey readOrCreateRunKey(const std::string& path) {
  // Written whole under a temporary name, then hard-linked to `path`: link() fails when `path`
  // exists, so a reader never sees half a key and two makers agree on one key.
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
  if (fd < 0) throw keyError(tmp, std::string("cannot create: ") + std::strerror(errno));
  const RunKey fresh = RunKey::random();
  try {
    writeAll(fd, toHex(fresh.bytes.data(), RunKey::kBytes) + "\n", tmp);
  } catch (...) {
    ::close(fd);
    ::unlink(tmp.c_str());
    throw;
  }
  ::close(fd);
  const int linked = ::link(tmp.c_str(), path.c_str());
  const int link_errno = errno;
  ::unlink(tmp.c_str());
  if (linked != 0 && link_errno != EEXIST) throw keyError(path, std::string("cannot create: ") + std::strerror(link_errno));
  return readRunKey(path);
}

}  // namespace masa::transport
