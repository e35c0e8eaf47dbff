// SASA-data (paper, offline section): the dataset augmented with the symmetric image of every
// transition under every group element, (T_i o, T_i a, r, T_i o', terminal, timeout) for i = 1..N-1,
// so that a single-agent learner sees the whole orbit of each sample.
#pragma once

#include "common/dataset/transition_dataset.hpp"
#include "common/symmetry/symmetry_spec.hpp"

namespace masa::offline {

// N x the transitions: image i of the whole dataset occupies columns [i*n, (i+1)*n) (image 0 is the
// dataset itself), each image's episodes contiguous as the dataset requires. Episodes keep their
// policy and result; image i's episode ids are original_id * N + i (unique, and the original
// readable back). Throws std::runtime_error when the dataset's dimensions are not the spec's.
dataset::TransitionDataset augmentWithSymmetricImages(const dataset::TransitionDataset& data,
                                                      const sym::SymmetrySpec& spec);

}  // namespace masa::offline
