// The learner's checkpoint: everything a resumed run needs to make the identical next update. The
// learner's counters and generator, then the algorithm's own part (learner/algorithm.hpp: PPO's
// learning rate, minibatch shuffle, model with normalizers and Adam moments; nothing for the
// off-policy learner, whose state is streamed beside it).
//
// Layout: sealed (common/integrity/sealed_file.hpp: SHA-256 checked before any byte is used), and
// inside the seal "MASACKP2", run id, update count, version, env steps, wall time, rng state text,
// the algorithm's kind (the run config's `learner`), its body. Written atomically (tmp + rename).
// Version 1 files ("MASACKP1": lr before the rng state, a PPO body in every run, unused in
// off-policy ones) still read, as kind "ppo" with `legacy` set.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

#include "common/integrity/sealed_file.hpp"

namespace masa::learner {

struct CheckpointState {
  int64_t run_id = 0;
  int64_t updates = 0;  // updates made; each one made one new policy version
  int64_t version = 0;
  int64_t env_steps = 0;
  double wall_time_s = 0;
  std::string rng_state;  // the generator's text form (operator<<)
  std::string kind;       // the algorithm's (Algorithm::kind)
  std::string body;       // the algorithm's bytes (Algorithm::saveCheckpointBody)
  bool legacy = false;    // read from a version 1 file
};

inline constexpr integrity::FileKind kCheckpointFileKind{"masa learner checkpoint", "MASACKP1"};

void writeCheckpoint(const std::string& path, const CheckpointState& state);

// Throws std::runtime_error naming the file and what is wrong.
CheckpointState readCheckpoint(const std::string& path);
// The same from a checkpoint file's bytes (data-parallel ranks get rank 0's file this way); `name`
// says where they came from in errors.
CheckpointState readCheckpointBytes(std::string bytes, const std::string& name);

bool isCheckpointFile(const std::string& path);

}  // namespace masa::learner
