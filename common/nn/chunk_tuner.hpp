// How many batch columns a thread of the fused MLP engine takes through all layers at a time.
//
// The best width is a cache question with no portable answer: a chunk's activations must stay in
// L2 next to the weights (and, in backward, their packed transpose), and how much room that leaves
// depends on the L2 size, the network and the prefetchers of the CPU (issue #14). Results do not
// depend on the width: every chunk is a whole number of 128-column blocks, the threads split the
// batch by blocks, and weight gradients are summed block by block in the same order whatever the
// chunk (mlp.cpp). So the width is chosen by measurement during the first training steps of each
// network on the machine it runs on: every candidate runs a few steps, timed per column, and the
// fastest is kept. Timing noise can only cost speed, never change a result.
#pragma once

#include <array>
#include <string>

namespace masa::nn {

class ChunkTuner {
 public:
  static constexpr int kBlock = 128;  // the summation block, and the unit of every width
  static constexpr std::array<int, 3> kCandidates{128, 256, 512};
  // Steps per candidate; the first one after a switch is not counted (its buffers are cold).
  static constexpr int kStepsPerCandidate = 3;

  // The width to use for a step of `columns_per_thread` columns on each thread: the candidate being
  // timed, or the choice, never wider than one thread's share (rounded up to a block).
  int width(int columns_per_thread) const;

  // One training step (forward + backward) of `columns` columns, `columns_per_thread` on each
  // thread, took `seconds` at width(columns_per_thread). Steps too small to fill the candidate
  // being timed do not count.
  void record(int columns, int columns_per_thread, double seconds);

  // Fixes the width (a positive multiple of kBlock); no more timing.
  void force(int width);

  bool settled() const { return chosen_ > 0; }
  // What decided the width: "256 columns (measured, us per column: 128 -> 1.23, ...)", or "forced".
  std::string summary() const;

 private:
  int candidate_ = 0;  // index into kCandidates being timed
  int steps_ = 0;      // steps recorded for it, the uncounted first included
  std::array<double, kCandidates.size()> best_{};  // seconds per column, 0 = not measured
  int chosen_ = 0;
  bool forced_ = false;
};

}  // namespace masa::nn
