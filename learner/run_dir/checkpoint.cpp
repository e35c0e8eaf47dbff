#include "learner/run_dir/checkpoint.hpp"

#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "common/core/binary_io.hpp"

namespace masa::learner {
namespace fs = std::filesystem;
namespace {

constexpr char kMagic[8] = {'M', 'A', 'S', 'A', 'C', 'K', 'P', '2'};
constexpr char kMagicV1[8] = {'M', 'A', 'S', 'A', 'C', 'K', 'P', '1'};

template <class T>
T readPod(std::istream& is, const std::string& path) {
  T v{};
  if (!io::readPod(is, v)) throw std::runtime_error(path + ": truncated checkpoint");
  return v;
}

void writeString(std::ostream& os, const std::string& s) {
  io::writePod(os, static_cast<uint64_t>(s.size()));
  io::writeArray(os, s.data(), s.size());
}

std::string readString(std::istream& is, const std::string& path, uint64_t max_size, const char* what) {
  const uint64_t n = readPod<uint64_t>(is, path);
  if (n > max_size) throw std::runtime_error(path + ": corrupt " + what);
  std::string s(n, '\0');
  if (!io::readArray(is, s.data(), n)) throw std::runtime_error(path + ": truncated checkpoint");
  return s;
}

CheckpointState parseCheckpoint(std::istream& is, const std::string& path) {
  char magic[sizeof kMagic];
  is.read(magic, sizeof magic);
  const bool v1 = is && std::memcmp(magic, kMagicV1, sizeof magic) == 0;
  if (!is || (!v1 && std::memcmp(magic, kMagic, sizeof magic) != 0))
    throw std::runtime_error(path + ": not a masa learner checkpoint (bad magic)");
  CheckpointState s;
  s.run_id = readPod<int64_t>(is, path);
  s.updates = readPod<int64_t>(is, path);
  s.version = readPod<int64_t>(is, path);
  s.env_steps = readPod<int64_t>(is, path);
  s.wall_time_s = readPod<double>(is, path);
  std::ostringstream body(std::ios::binary);
  if (v1) {
    // lr, then the rng state, then PPO's shuffle, model and Adam: the body is lr and what follows.
    io::writePod(body, readPod<double>(is, path));
    s.kind = "ppo";
    s.legacy = true;
  }
  s.rng_state = readString(is, path, 1u << 20, "rng state");
  if (!v1) s.kind = readString(is, path, 64, "algorithm kind");
  body << is.rdbuf();
  s.body = std::move(body).str();
  return s;
}

}  // namespace

void writeCheckpoint(const std::string& path, const CheckpointState& s) {
  std::ostringstream os(std::ios::binary);
  os.write(kMagic, sizeof kMagic);
  io::writePod(os, s.run_id);
  io::writePod(os, s.updates);
  io::writePod(os, s.version);
  io::writePod(os, s.env_steps);
  io::writePod(os, s.wall_time_s);
  writeString(os, s.rng_state);
  writeString(os, s.kind);
  io::writeArray(os, s.body.data(), s.body.size());
  if (!os) throw std::runtime_error("checkpoint: cannot serialize " + path);
  // Atomic: a crash leaves the old or the new checkpoint, never half of one.
  integrity::writeSealedFile(path, kCheckpointFileKind, os.view());
}

bool isCheckpointFile(const std::string& path) { return integrity::looksLikeKind(path, kCheckpointFileKind); }

CheckpointState readCheckpointBytes(std::string bytes, const std::string& name) {
  const integrity::OpenedFile file = integrity::openSealedBytes(std::move(bytes), name, kCheckpointFileKind);
  std::istringstream is(file.payload, std::ios::binary);
  return parseCheckpoint(is, name);
}

CheckpointState readCheckpoint(const std::string& path) {
  if (!fs::exists(path)) throw std::runtime_error(path + ": cannot open the checkpoint (no such file)");
  const integrity::OpenedFile file = integrity::readSealedFile(path, kCheckpointFileKind);
  std::istringstream is(file.payload, std::ios::binary);
  return parseCheckpoint(is, path);
}

}  // namespace masa::learner
