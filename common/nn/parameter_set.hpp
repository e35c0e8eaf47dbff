// One flat, contiguous vector of parameters and one of gradients for a whole model.
//
// Layers reserve named segments before finalize() allocates; afterwards they read their weights
// through offsets (never cached pointers), so loading or broadcasting parameters is one memcpy and
// Adam, grad-norm clipping and checkpoints work on a single vector.
#pragma once

#include <string>
#include <vector>

#include "common/core/check.hpp"
#include "common/core/types.hpp"

namespace masa::nn {

struct ParameterSegment {
  std::string name;  // e.g. "policy.phi.layer0.weight"
  int offset = 0;
  int rows = 0;  // a segment is a rows x cols column-major matrix (cols = 1 for vectors)
  int cols = 0;
  int size() const { return rows * cols; }
};

template <typename S>
class ParameterSet {
 public:
  // Reserves rows*cols scalars; returns the offset. Only before finalize(); names must be unique.
  int reserve(const std::string& name, int rows, int cols = 1);
  // Allocates values and gradients (zeroed). Idempotent.
  void finalize();
  bool finalized() const { return finalized_; }

  int size() const { return size_; }
  const std::vector<ParameterSegment>& segments() const { return segments_; }
  const ParameterSegment& segment(const std::string& name) const;  // throws if unknown

  // A frozen set (a deployed policy's) can no longer be written: the mutable accessors throw, so
  // inference may keep packed copies of the weights (Mlp::infer) without their going stale.
  void freeze() { frozen_ = true; }
  bool frozen() const { return frozen_; }

  Vec<S>& values() {
    MASA_CHECK(!frozen_, "the parameters are frozen for inference and cannot be written");
    return values_;
  }
  const Vec<S>& values() const { return values_; }
  Vec<S>& grads() { return grads_; }
  const Vec<S>& grads() const { return grads_; }
  void zeroGrad() { grads_.setZero(); }

  // Views of one segment as a matrix.
  Eigen::Map<Mat<S>> value(int offset, int rows, int cols);
  Eigen::Map<const Mat<S>> value(int offset, int rows, int cols) const;
  Eigen::Map<Mat<S>> grad(int offset, int rows, int cols);

 private:
  std::vector<ParameterSegment> segments_;
  int size_ = 0;
  bool finalized_ = false;
  bool frozen_ = false;
  Vec<S> values_;
  Vec<S> grads_;
};

}  // namespace masa::nn
