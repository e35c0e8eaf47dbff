#include "common/nn/chunk_tuner.hpp"

#include <algorithm>
#include <cstdio>

#include "common/core/check.hpp"

namespace masa::nn {

namespace {
int roundUpToBlock(int columns) {
  return (std::max(columns, 1) + ChunkTuner::kBlock - 1) / ChunkTuner::kBlock * ChunkTuner::kBlock;
}
}  // namespace

int ChunkTuner::width(int columns_per_thread) const {
  const int w = settled() ? chosen_ : kCandidates[candidate_];
  return std::min(w, roundUpToBlock(columns_per_thread));
}

void ChunkTuner::record(int columns, int columns_per_thread, double seconds) {
  if (settled() || columns <= 0) return;
  auto settle = [&] {
    int best = 0;
    for (size_t c = 1; c < kCandidates.size(); ++c)
      if (best_[c] > 0 && best_[c] < best_[best]) best = static_cast<int>(c);
    chosen_ = kCandidates[best];
  };
  // A batch whose share per thread is narrower than this candidate cannot tell it from a
  // narrower one, nor any wider candidate: the widths measured so far decide.
  // (Never the first candidate: one block always fits.)
  if (kCandidates[candidate_] > roundUpToBlock(columns_per_thread)) return settle();
  if (steps_++ > 0) {
    const double per_column = seconds / columns;
    double& best = best_[candidate_];
    best = best == 0 ? per_column : std::min(best, per_column);
  }
  if (steps_ < kStepsPerCandidate) return;
  steps_ = 0;
  if (++candidate_ == static_cast<int>(kCandidates.size())) {
    candidate_ = 0;
    settle();
  }
}

void ChunkTuner::force(int width) {
  MASA_CHECK(width > 0 && width % kBlock == 0, "chunk width " << width << " is not a positive multiple of " << kBlock);
  chosen_ = width;
  forced_ = true;
}

std::string ChunkTuner::summary() const {
  std::string s;
  if (forced_) return std::to_string(chosen_) + " columns (forced)";
  s = settled() ? std::to_string(chosen_) + " columns (measured" : "not chosen yet (timing";
  s += ", us per column:";
  char buf[64];
  for (size_t c = 0; c < kCandidates.size(); ++c) {
    if (best_[c] <= 0) continue;
    std::snprintf(buf, sizeof buf, " %d -> %.3f", kCandidates[c], best_[c] * 1e6);
    s += buf;
  }
  return s + ")";
}

}  // namespace masa::nn
