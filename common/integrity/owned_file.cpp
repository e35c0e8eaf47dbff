#include "common/integrity/owned_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace masa::integrity {

namespace {

std::string octal(mode_t mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", static_cast<unsigned>(mode & 07777));
  return text;
}

bool ownedByUserOrRoot(const struct stat& st) { return st.st_uid == ::geteuid() || st.st_uid == 0; }

class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

void checkDirectory(const std::string& path, const std::string& what) {
  // A file named without a directory is in the working one. (Built, not assigned: GCC 12's
  // -Wstringop-overflow misfires on assigning "." to the string.)
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  const std::string dir = parent.empty() ? std::string(".") : parent.string();
  const Descriptor fd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  struct stat st {};
  if (fd.get() < 0 || ::fstat(fd.get(), &st) != 0)
    throw std::runtime_error(what + " " + path + ": cannot open its directory " + dir + " (" + std::strerror(errno) + ")");
  if (!ownedByUserOrRoot(st))
    throw std::runtime_error(what + " " + path + ": its directory " + dir + " belongs to user " + std::to_string(st.st_uid) +
                             ", who could put another file in its place (keep it in a directory of yours)");
  if ((st.st_mode & 022) != 0)
    throw std::runtime_error(what + " " + path + ": others may write its directory " + dir + " (mode " + octal(st.st_mode) +
                             "), so anyone could put another file in its place (chmod go-w " + dir + ")");
}

}  // namespace

std::string readOwnedFile(const std::string& path, const std::string& what, FileSecrecy secrecy) {
  // O_NOFOLLOW: a link's target lies in a directory nobody checked. O_NONBLOCK: a FIFO planted
  // there must not hang the open (it is then refused as not a regular file).
  const Descriptor fd(::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0) {
    const int err = errno;
    throw std::runtime_error(what + " " + path + ": cannot open it (" + std::strerror(err) +
                             (err == ELOOP ? "; a symbolic link is not followed, give the file itself" : "") + ")");
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) throw std::runtime_error(what + " " + path + ": cannot stat it");
  if (!S_ISREG(st.st_mode)) throw std::runtime_error(what + " " + path + ": not a regular file");
  if (!ownedByUserOrRoot(st))
    throw std::runtime_error(what + " " + path + ": it belongs to user " + std::to_string(st.st_uid) + ", not to user " +
                             std::to_string(::geteuid()) + " who runs this or root, so whoever owns it decides what is believed");
  if (secrecy == FileSecrecy::kSecret && (st.st_mode & 077) != 0)
    throw std::runtime_error(what + " " + path + ": a private key readable by others than its owner is refused (mode " +
                             octal(st.st_mode) + "; chmod 600 " + path + ")");
  if ((st.st_mode & 022) != 0)
    throw std::runtime_error(what + " " + path + ": others may write it (mode " + octal(st.st_mode) +
                             "), so anyone could add a key that is then believed (chmod go-w " + path + ")");
  checkDirectory(path, what);
  std::string bytes;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(fd.get(), buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw std::runtime_error(what + " " + path + ": cannot read it (" + std::strerror(errno) + ")");
    if (n == 0) break;
    bytes.append(buffer, static_cast<std::size_t>(n));
    if (bytes.size() > (std::size_t{1} << 26)) throw std::runtime_error(what + " " + path + ": larger than 64 MiB");
  }
  return bytes;
}

}  // namespace masa::integrity
