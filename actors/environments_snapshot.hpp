// masa_train's exact resume: the actor's environments between two rollouts, kept in memory at every
// rollout boundary and written beside the learner's checkpoint when one is written for that same
// update (actor_state.bin, sealed: common/integrity/sealed_file.hpp; inside the seal a line naming
// the format, the update, then Actor::saveEnvironments).
// A run stopped in the middle of a rollout still writes the environments of the last boundary,
// which is where its learner's checkpoint stands.
#pragma once

#include <cstdint>
#include <string>

#include "actors/actor.hpp"
#include "common/integrity/sealed_file.hpp"

namespace masa::actor {

inline constexpr integrity::FileKind kEnvironmentsFileKind{"masa actor environments", "masa actor environments 1\n"};

class EnvironmentsSnapshot {
 public:
  // The actor's environments now, as they will be paired with the learner's update `update`.
  void take(const Actor& actor, int64_t update);
  // Writes the snapshot to `path` (atomically: a temporary file renamed) when it is of `update`.
  void writeIfAt(int64_t update, const std::string& path) const;

 private:
  std::string bytes_;
  int64_t update_ = -1;
};

// Loads `path` into the actor when it holds the environments of update `update`. Returns "" when
// it did, else why not (no file, another update); throws on a file that is corrupt (its checksum
// fails) or not this actor's (another task, another number of environments).
std::string resumeEnvironments(const std::string& path, int64_t update, Actor& actor);

}  // namespace masa::actor
