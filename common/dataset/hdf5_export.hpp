// A dataset as one HDF5 file, laid out the way offline-RL code in Python expects (D4RL's names):
//   observations, next_observations  float32 [N, obs_dim]
//   actions                          float32 [N, act_dim]
//   rewards                          float32 [N]
//   terminals, timeouts              uint8   [N]
//   episode_index                    int64   [N]   (row of episodes/* each transition belongs to)
//   episodes/{id, start, length, return, success, policy}   one row per episode
// and attributes task, obs_dim, act_dim, policy_names (newline-separated), source.
// In Python:  f = h5py.File("data.h5");  obs = f["observations"][:];  act = f["actions"][:]
#pragma once

#include <string>

#include "common/dataset/transition_dataset.hpp"

namespace masa::dataset {

// Writes (replacing) `path` atomically (tmp + rename). Throws std::runtime_error on failure.
void writeHdf5(const std::string& path, const TransitionDataset& d, const std::string& source = "");

// Reads a file written by writeHdf5 (for tests and for training from an exported file).
TransitionDataset readHdf5(const std::string& path);

}  // namespace masa::dataset
