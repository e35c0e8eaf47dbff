// The learner's checkpoint: everything a resumed run needs to make the identical next update
// (counters, lr, random state, minibatch shuffle, model with normalizers, Adam moments). The
// model part is the same as a policy file's, so a checkpoint can also be evaluated directly.
//
// Layout: sealed (common/integrity/sealed_file.hpp: SHA-256 checked before any byte is used), and
// inside the seal "MASACKP1", run id, update count, version, env steps, wall time, lr, rng state
// text, shuffle order, ActorCritic::save(), Adam::save(). Written atomically (tmp + rename).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "common/integrity/sealed_file.hpp"
#include "common/model/actor_critic.hpp"
#include "common/nn/adam.hpp"

namespace masa::learner {

struct CheckpointState {
  int64_t run_id = 0;
  int64_t updates = 0;  // updates made; each one made one new policy version
  int64_t version = 0;
  int64_t env_steps = 0;
  double wall_time_s = 0;
  double lr = 0;
  std::string rng_state;   // the generator's text form (operator<<)
  std::vector<int> order;  // the PPO minibatch shuffle
};

inline constexpr integrity::FileKind kCheckpointFileKind{"masa learner checkpoint", "MASACKP1"};

void writeCheckpoint(const std::string& path, const CheckpointState& state, const model::ActorCritic<float>& model,
                     const nn::Adam<float>& adam);

// Reads the state and loads the model; loads the optimizer too unless `adam` is null (evaluation).
// Throws std::runtime_error naming the file and what is wrong.
CheckpointState readCheckpoint(const std::string& path, model::ActorCritic<float>& model, nn::Adam<float>* adam);
// The same from a checkpoint file's bytes (data-parallel ranks get rank 0's file this way); `name`
// says where they came from in errors.
CheckpointState readCheckpointBytes(std::string bytes, const std::string& name, model::ActorCritic<float>& model,
                                    nn::Adam<float>* adam);

bool isCheckpointFile(const std::string& path);

}  // namespace masa::learner
