#include "learner/checkpoint.hpp"

#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "common/core/binary_io.hpp"

namespace masa::learner {
namespace fs = std::filesystem;
namespace {

constexpr char kMagic[8] = {'M', 'A', 'S', 'A', 'C', 'K', 'P', '1'};

using io::writeArray;
using io::writePod;

template <class T>
T readPod(std::istream& is, const std::string& path) {
  T v{};
  if (!io::readPod(is, v)) throw std::runtime_error(path + ": truncated checkpoint");
  return v;
}

}  // namespace

void writeCheckpoint(const std::string& path, const CheckpointState& s, const model::ActorCritic<float>& model,
                     const nn::Adam<float>& adam) {
  std::ostringstream os(std::ios::binary);
  os.write(kMagic, sizeof kMagic);
  writePod(os, s.run_id);
  writePod(os, s.updates);
  writePod(os, s.version);
  writePod(os, s.env_steps);
  writePod(os, s.wall_time_s);
  writePod(os, s.lr);
  writePod(os, static_cast<uint64_t>(s.rng_state.size()));
  writeArray(os, s.rng_state.data(), s.rng_state.size());
  writePod(os, static_cast<uint64_t>(s.order.size()));
  writeArray(os, s.order.data(), s.order.size());
  model.save(os);
  adam.save(os);
  if (!os) throw std::runtime_error("checkpoint: cannot serialize " + path);
  // Atomic: a crash leaves the old or the new checkpoint, never half of one.
  integrity::writeSealedFile(path, kCheckpointFileKind, os.view());
}

bool isCheckpointFile(const std::string& path) { return integrity::looksLikeKind(path, kCheckpointFileKind); }

namespace {

CheckpointState parseCheckpoint(std::istream& is, const std::string& path, model::ActorCritic<float>& model,
                                nn::Adam<float>* adam) {
  char magic[sizeof kMagic];
  is.read(magic, sizeof magic);
  if (!is || std::memcmp(magic, kMagic, sizeof magic) != 0)
    throw std::runtime_error(path + ": not a masa learner checkpoint (bad magic)");
  CheckpointState s;
  s.run_id = readPod<int64_t>(is, path);
  s.updates = readPod<int64_t>(is, path);
  s.version = readPod<int64_t>(is, path);
  s.env_steps = readPod<int64_t>(is, path);
  s.wall_time_s = readPod<double>(is, path);
  s.lr = readPod<double>(is, path);
  const uint64_t rn = readPod<uint64_t>(is, path);
  if (rn > (1u << 20)) throw std::runtime_error(path + ": corrupt rng state");
  s.rng_state.assign(rn, '\0');
  if (!io::readArray(is, s.rng_state.data(), rn)) throw std::runtime_error(path + ": truncated checkpoint");
  const uint64_t on = readPod<uint64_t>(is, path);
  if (on > (1ull << 31)) throw std::runtime_error(path + ": corrupt shuffle order");
  s.order.resize(on);
  if (!io::readArray(is, s.order.data(), on)) throw std::runtime_error(path + ": truncated checkpoint");
  model.load(is, path);
  if (adam) {
    adam->load(is);
    if (is.peek() != std::char_traits<char>::eof()) throw std::runtime_error(path + ": bytes after the optimizer (corrupt checkpoint)");
  }
  return s;
}

}  // namespace

CheckpointState readCheckpointBytes(std::string bytes, const std::string& name, model::ActorCritic<float>& model,
                                    nn::Adam<float>* adam) {
  const integrity::OpenedFile file = integrity::openSealedBytes(std::move(bytes), name, kCheckpointFileKind);
  std::istringstream is(file.payload, std::ios::binary);
  return parseCheckpoint(is, name, model, adam);
}

CheckpointState readCheckpoint(const std::string& path, model::ActorCritic<float>& model, nn::Adam<float>* adam) {
  if (!fs::exists(path)) throw std::runtime_error(path + ": cannot open the checkpoint (no such file)");
  const integrity::OpenedFile file = integrity::readSealedFile(path, kCheckpointFileKind);
  std::istringstream is(file.payload, std::ios::binary);
  return parseCheckpoint(is, path, model, adam);
}

}  // namespace masa::learner
