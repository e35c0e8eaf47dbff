#include "common/nn/gemm.hpp"

#include <omp.h>

#include <algorithm>

#include "common/core/check.hpp"

namespace masa::nn {

namespace {

using Eigen::Index;

// Below this many FLOP a product stays on the calling thread: waking a second one costs more.
constexpr double kParallelFlops = 8e6;
// Column chunks handed to threads are multiples of this (a multiple of every kernel's nr).
constexpr Index kColumnGrain = 16;

// Hands Eigen's kernel our buffers and blocking instead of letting it allocate its own.
template <typename S>
class FixedBlocking : public Eigen::internal::level3_blocking<S, S> {
 public:
  FixedBlocking(const GemmPlan& plan, S* block_a, S* block_b) {
    this->m_kc = plan.kc;
    this->m_mc = plan.mc;
    this->m_nc = plan.nc;
    this->m_blockA = block_a;
    this->m_blockB = block_b;
  }
};

template <typename S, int AOrder, int BOrder>
void kernel(Index m, Index n, Index k, const S* a, Index lda, const S* b, Index ldb, S* c, Index ldc,
            FixedBlocking<S>& blocking) {
  Eigen::internal::general_matrix_matrix_product<Index, S, AOrder, false, S, BOrder, false, Eigen::ColMajor, 1>::run(
      m, n, k, a, lda, b, ldb, c, 1, ldc, S(1), blocking, nullptr);
}

template <typename S>
void kernel(bool trans_a, bool trans_b, Index m, Index n, Index k, const S* a, Index lda, const S* b, Index ldb, S* c,
            Index ldc, FixedBlocking<S>& blocking) {
  // A transposed column-major operand is the same memory read row-major.
  constexpr int C = Eigen::ColMajor, R = Eigen::RowMajor;
  if (!trans_a && !trans_b) kernel<S, C, C>(m, n, k, a, lda, b, ldb, c, ldc, blocking);
  if (!trans_a && trans_b) kernel<S, C, R>(m, n, k, a, lda, b, ldb, c, ldc, blocking);
  if (trans_a && !trans_b) kernel<S, R, C>(m, n, k, a, lda, b, ldb, c, ldc, blocking);
  if (trans_a && trans_b) kernel<S, R, R>(m, n, k, a, lda, b, ldb, c, ldc, blocking);
}

}  // namespace

template <typename S>
GemmPlan GemmWorkspace<S>::plan(Index m, Index n, Index k) {
  GemmPlan p{std::max<Index>(k, 1), std::max<Index>(m, 1), std::max<Index>(n, 1)};
  Eigen::internal::computeProductBlockingSizes<S, S, 1, Index>(p.kc, p.mc, p.nc, Index(1));
  return p;
}

template <typename S>
void GemmWorkspace<S>::reserve(const std::vector<GemmPlan>& plans) {
  const size_t threads = static_cast<size_t>(std::max(1, omp_get_max_threads()));
  if (threads_.size() < threads) threads_.resize(threads);
  for (Buffers& t : threads_)
    for (const GemmPlan& p : plans) {
      if (t.a.size() < p.kc * p.mc) t.a.resize(p.kc * p.mc);
      if (t.b.size() < p.kc * p.nc) t.b.resize(p.kc * p.nc);
    }
}

template <typename S>
void GemmWorkspace<S>::run(const GemmPlan& plan, bool trans_a, bool trans_b, Index m, Index n, Index k, const S* a,
                           Index lda, const S* b, Index ldb, S* c, Index ldc, bool accumulate) {
  using StridedMap = Eigen::Map<Mat<S>, 0, Eigen::OuterStride<>>;
  if (!accumulate) StridedMap(c, m, n, Eigen::OuterStride<>(ldc)).setZero();
  if (m == 0 || n == 0 || k == 0) return;
  MASA_CHECK(!threads_.empty(), "GemmWorkspace::run before reserve()");

  if (n == 1 && !trans_b) {
    // One column: Eigen's GEMV needs no packing and no buffer.
    using ConstStridedMap = Eigen::Map<const Mat<S>, 0, Eigen::OuterStride<>>;
    Eigen::Map<const Vec<S>> x(b, k);
    Eigen::Map<Vec<S>> y(c, m);
    if (trans_a)
      y.noalias() += ConstStridedMap(a, k, m, Eigen::OuterStride<>(lda)).transpose() * x;
    else
      y.noalias() += ConstStridedMap(a, m, k, Eigen::OuterStride<>(lda)) * x;
    return;
  }

  const GemmPlan clamped{std::min(plan.kc, k), std::min(plan.mc, m), plan.nc};
  int threads = std::min<int>(static_cast<int>(threads_.size()), omp_get_max_threads());
  threads = std::min<int>(threads, static_cast<int>((n + kColumnGrain - 1) / kColumnGrain));
  if (2.0 * m * n * k < kParallelFlops || omp_in_parallel()) threads = 1;

  auto columns = [&](int t, int nt) {
    const Index chunk = ((n + nt - 1) / nt + kColumnGrain - 1) / kColumnGrain * kColumnGrain;
    const Index j0 = std::min(n, t * chunk), j1 = std::min(n, j0 + chunk);
    if (j1 <= j0) return;
    FixedBlocking<S> blocking(clamped, threads_[t].a.data(), threads_[t].b.data());
    const S* bj = trans_b ? b + j0 : b + j0 * ldb;
    kernel<S>(trans_a, trans_b, m, j1 - j0, k, a, lda, bj, ldb, c + j0 * ldc, ldc, blocking);
  };
  if (threads == 1) {
    columns(0, 1);
    return;
  }
#pragma omp parallel num_threads(threads)
  columns(omp_get_thread_num(), omp_get_num_threads());
}

template class GemmWorkspace<float>;
template class GemmWorkspace<double>;

}  // namespace masa::nn
