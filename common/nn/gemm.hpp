// Matrix products for the MLP on packing buffers owned by the caller.
//
// Eigen's own GEMM packs its operands into buffers it allocates on every call once they exceed
// 128 KiB, and its OpenMP path allocates always; a training step would then call malloc dozens of
// times. Here the blocking is planned once for the largest shape (plan()), the buffers are sized
// then (reserve()), and run() only reuses them. Large products are split by columns of C over the
// OpenMP threads, each with its own buffers. Uses Eigen 3.4's internal GEMM kernel.
#pragma once

#include <vector>

#include "common/core/types.hpp"

namespace masa::nn {

// Cache blocking of one product, computed by Eigen's heuristic for its largest shape; smaller
// shapes use it clamped to their size, so they never need bigger buffers.
struct GemmPlan {
  Eigen::Index kc = 0, mc = 0, nc = 0;
};

template <typename S>
class GemmWorkspace {
 public:
  // Plan for C (m x n) = op(A) op(B) with inner dimension k.
  static GemmPlan plan(Eigen::Index m, Eigen::Index n, Eigen::Index k);
  // Grows the buffers of every thread to cover `plans` (allocates; call outside the hot loop).
  void reserve(const std::vector<GemmPlan>& plans);

  // C = op(A) op(B), or C += op(A) op(B) when accumulate. A is m x k after op, B is k x n after op;
  // all column-major with leading dimensions lda, ldb, ldc. Allocates nothing.
  void run(const GemmPlan& plan, bool trans_a, bool trans_b, Eigen::Index m, Eigen::Index n, Eigen::Index k,
           const S* a, Eigen::Index lda, const S* b, Eigen::Index ldb, S* c, Eigen::Index ldc, bool accumulate);

 private:
  struct Buffers {
    Vec<S> a, b;
  };
  std::vector<Buffers> threads_;
};

}  // namespace masa::nn
