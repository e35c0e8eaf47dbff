// The kernels of dense_kernels.hpp for CPUs with AVX2 and FMA but without AVX-512 (AMD Zen 2/3,
// Intel before Skylake-X). Without them such a CPU ran the generic engine: Eigen's GEMM with its
// packing, then bias, activation and derivative as separate passes over memory, about a fifth of
// an off-policy gradient step on Zen 3 (docs/benchmarks.md, issue #50).
//
// The same scheme as the AVX-512 kernels with 16 ymm registers instead of 32 zmm: tiles of up to
// 3 vectors (24 rows) x 4 columns, 12 accumulators, plus 3 vectors of the panel and one broadcast.
// Forward over 1-3 columns uses narrow tiles of up to 12, 6 or 4 vectors (one row of W at a time,
// used by every column). Every result element is summed over k in order from zero, whatever tile
// computes it, so a column's bits do not depend on the columns beside it. The last partial vector
// of a panel is read and written with AVX2's masked loads and stores.
#include "common/nn/dense_kernels.hpp"

#if defined(MASA_DENSE_AVX2)

#include <immintrin.h>

#include <algorithm>
#include <type_traits>
#include <vector>

#include "common/core/check.hpp"
#include "common/core/types.hpp"

namespace masa::nn::dense {

namespace {

// Splits ceil(rows / 8) vectors into panels of 3 vectors, with 2-vector panels for a remainder
// (v = 3q + 1 as 3(q-1) + 2 + 2): a 2 x 4 tile still has 8 FMA chains in flight, a 1 x 4 one
// only 4, too few for the FMA latency on two ports.
template <class F>
void forEachPanel(int rows, F&& f) {  // f(first row, vectors)
  const int v = (rows + kLanes - 1) / kLanes;
  if (v == 1) return f(0, 1);
  int threes = v / 3, twos = 0;
  if (v % 3 == 2) twos = 1;
  if (v % 3 == 1) --threes, twos = 2;
  int row0 = 0;
  for (int p = 0; p < threes; ++p, row0 += 3 * kLanes) f(row0, 3);
  for (int p = 0; p < twos; ++p, row0 += 2 * kLanes) f(row0, 2);
}

// Vectors of a narrow forward tile over nr columns: nr x vectors accumulators, nr broadcasts and
// one row of W fit the 16 registers. Four columns take the ordinary 3-vector tile.
constexpr int narrowVectors(int nr) { return nr == 1 ? 12 : nr == 2 ? 6 : nr == 3 ? 4 : 3; }

// Splits ceil(rows / 8) vectors into blocks of at most max_vectors, sized evenly.
// f(first row, vectors, last block).
template <class F>
void forEachNarrowBlock(int rows, int max_vectors, F&& f) {
  const int vectors = (rows + kLanes - 1) / kLanes;
  const int blocks = (vectors + max_vectors - 1) / max_vectors;
  const int base = vectors / blocks, extra = vectors % blocks;
  int row0 = 0;
  for (int b = 0; b < blocks; ++b) {
    const int mv = base + (b < extra ? 1 : 0);
    f(row0, mv, b == blocks - 1);
    row0 += mv * kLanes;
  }
}

constexpr int kTileCols = 4;
// Batch columns per weight-gradient block: g's and x's blocks stay in L2 while every tile of dw
// passes over them.
constexpr int kDepthBlock = 128;

template <int N>
using Int = std::integral_constant<int, N>;

using Mask = __m256i;  // a lane is loaded and stored where its sign bit is set

Mask firstLanes(int valid) {
  return _mm256_cmpgt_epi32(_mm256_set1_epi32(valid), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
}

// `masked` is a constant once the tile loops are unrolled.
inline __m256 loadRow(const float* p, bool masked, Mask mask) {
  return masked ? _mm256_maskload_ps(p, mask) : _mm256_loadu_ps(p);
}

inline void storeRow(float* p, __m256 v, bool masked, Mask mask) {
  if (masked)
    _mm256_maskstore_ps(p, mask, v);
  else
    _mm256_storeu_ps(p, v);
}

template <Activation A>
inline __m256 activation(__m256 z) {
  const __m256 zero = _mm256_setzero_ps();
  if constexpr (A == Activation::kIdentity) {
    return z;
  } else if constexpr (A == Activation::kRelu) {
    return _mm256_max_ps(z, zero);
  } else if constexpr (A == Activation::kElu) {
    // As in activation.cpp: y == z exactly for z > 0.
    const __m256 e = _mm256_sub_ps(Eigen::internal::pexp(_mm256_min_ps(z, zero)), _mm256_set1_ps(1.f));
    return _mm256_add_ps(_mm256_max_ps(z, zero), e);
  } else {
    return Eigen::internal::ptanh(z);
  }
}

// f'(z) from y = f(z).
template <Activation A>
inline __m256 derivative(__m256 y) {
  const __m256 one = _mm256_set1_ps(1.f);
  if constexpr (A == Activation::kRelu) {
    return _mm256_and_ps(_mm256_cmp_ps(y, _mm256_setzero_ps(), _CMP_GT_OQ), one);
  } else if constexpr (A == Activation::kElu) {
    return _mm256_add_ps(_mm256_min_ps(y, _mm256_setzero_ps()), one);
  } else {
    return _mm256_sub_ps(one, _mm256_mul_ps(y, y));
  }
}

// acc = rows of a (MV vectors, the last one masked when kMasked; column k at a + k * lda) times
// columns [0, NR) of b (depth x NR, ldb).
template <int MV, int NR, bool kMasked>
inline void panelTimesColumns(const float* __restrict a, Index lda, int depth, const float* __restrict b, Index ldb,
                              Mask mask, __m256 (&acc)[MV][NR]) {
#pragma GCC unroll 4
  for (int j = 0; j < NR; ++j)
#pragma GCC unroll 12
    for (int i = 0; i < MV; ++i) acc[i][j] = _mm256_setzero_ps();
  const float* col[NR];
#pragma GCC unroll 4
  for (int j = 0; j < NR; ++j) col[j] = b + j * ldb;
  if constexpr (MV > 3) {
    // Narrow tiles: the NR broadcasts first, then one row of W at a time, used by all NR columns.
    // The empty asm keeps the row in a register instead of folding its load into each FMA.
    for (int k = 0; k < depth; ++k, a += lda) {
      __m256 bj[NR];
#pragma GCC unroll 4
      for (int j = 0; j < NR; ++j) bj[j] = _mm256_broadcast_ss(col[j] + k);
#pragma GCC unroll 12
      for (int i = 0; i < MV; ++i) {
        __m256 av = loadRow(a + i * kLanes, kMasked && i == MV - 1, mask);
        if constexpr (NR > 1) __asm__("" : "+x"(av));
#pragma GCC unroll 4
        for (int j = 0; j < NR; ++j) acc[i][j] = _mm256_fmadd_ps(av, bj[j], acc[i][j]);
      }
    }
  } else {
    for (int k = 0; k < depth; ++k, a += lda) {
      // The empty asm keeps each vector of the panel in a register: left alone, GCC folds its load
      // into each of the NR FMAs, and 3 x 4 + 4 loads for 12 FMAs make the loop load-bound (two
      // 256-bit loads a cycle on Zen 3): 0.37 of peak instead of the kernel's 0.8.
      __m256 av[MV];
#pragma GCC unroll 3
      for (int i = 0; i < MV; ++i) {
        av[i] = loadRow(a + i * kLanes, kMasked && i == MV - 1, mask);
        if constexpr (NR > 1) __asm__("" : "+x"(av[i]));
      }
#pragma GCC unroll 4
      for (int j = 0; j < NR; ++j) {
        const __m256 bj = _mm256_broadcast_ss(col[j] + k);
#pragma GCC unroll 3
        for (int i = 0; i < MV; ++i) acc[i][j] = _mm256_fmadd_ps(av[i], bj, acc[i][j]);
      }
    }
  }
}

template <Activation A, int MV, int NR, bool kMasked>
void forwardTile(const float* a, Index lda, int depth, const float* bias, const float* x, Index ldx, float* y,
                 Index ldy, Mask mask) {
  __m256 acc[MV][NR];
  panelTimesColumns<MV, NR, kMasked>(a, lda, depth, x, ldx, mask, acc);
  // z = acc + bias, activated tile by tile column by column (the activation's temporaries then
  // fit beside the accumulators).
#pragma GCC unroll 4
  for (int j = 0; j < NR; ++j)
#pragma GCC unroll 12
    for (int i = 0; i < MV; ++i) {
      const bool masked = kMasked && i == MV - 1;
      const __m256 b = bias ? loadRow(bias + i * kLanes, masked, mask) : _mm256_setzero_ps();
      storeRow(y + j * ldy + i * kLanes, activation<A>(_mm256_add_ps(acc[i][j], b)), masked, mask);
    }
}

template <Activation A, int MV, int NR, bool kMasked>
void inputGradTile(const float* a, Index lda, int depth, const float* g, Index ldg, const float* y, Index ldy,
                   float* d, Index ldd, Mask mask) {
  __m256 acc[MV][NR];
  panelTimesColumns<MV, NR, kMasked>(a, lda, depth, g, ldg, mask, acc);
#pragma GCC unroll 4
  for (int j = 0; j < NR; ++j)
#pragma GCC unroll 3
    for (int i = 0; i < MV; ++i) {
      __m256 v = acc[i][j];
      if constexpr (A != Activation::kIdentity)
        v = _mm256_mul_ps(v, derivative<A>(loadRow(y + j * ldy + i * kLanes, kMasked && i == MV - 1, mask)));
      storeRow(d + j * ldd + i * kLanes, v, kMasked && i == MV - 1, mask);
    }
}

// dw tile (MV vectors of rows x NR columns) += g x^T over n batch columns.
template <int MV, int NR, bool kMasked>
void weightGradTile(int n, const float* __restrict g, Index ldg, const float* __restrict x, Index ldx,
                    float* __restrict dw, Index lddw, Mask mask) {
  __m256 acc[MV][NR];
#pragma GCC unroll 3
  for (int i = 0; i < MV; ++i)
#pragma GCC unroll 4
    for (int j = 0; j < NR; ++j) acc[i][j] = _mm256_setzero_ps();
  for (int k = 0; k < n; ++k, g += ldg, x += ldx) {
    // The next cache line of this column of x is the one the tiles four to the right need: its
    // columns are scattered (one line each), so the hardware prefetcher does not bring them.
    _mm_prefetch(reinterpret_cast<const char*>(x + 16), _MM_HINT_T0);
    __m256 av[MV];  // (kept in registers, as in panelTimesColumns)
#pragma GCC unroll 3
    for (int i = 0; i < MV; ++i) {
      av[i] = loadRow(g + i * kLanes, kMasked && i == MV - 1, mask);
      if constexpr (NR > 1) __asm__("" : "+x"(av[i]));
    }
#pragma GCC unroll 4
    for (int j = 0; j < NR; ++j) {
      const __m256 xj = _mm256_broadcast_ss(x + j);
#pragma GCC unroll 3
      for (int i = 0; i < MV; ++i) acc[i][j] = _mm256_fmadd_ps(av[i], xj, acc[i][j]);
    }
  }
#pragma GCC unroll 4
  for (int j = 0; j < NR; ++j)
#pragma GCC unroll 3
    for (int i = 0; i < MV; ++i) {
      float* p = dw + j * lddw + i * kLanes;
      const bool masked = kMasked && i == MV - 1;
      storeRow(p, _mm256_add_ps(loadRow(p, masked, mask), acc[i][j]), masked, mask);
    }
}

// db (MV vectors) += row sums of g over n columns. Its own pass (the AVX-512 kernel sums them in
// the first dw tile): 3 more accumulators there would not fit the 16 registers.
template <int MV, bool kMasked>
void rowSumTile(int n, const float* __restrict g, Index ldg, float* __restrict db, Mask mask) {
  __m256 sum[MV];
#pragma GCC unroll 3
  for (int i = 0; i < MV; ++i) sum[i] = _mm256_setzero_ps();
  for (int k = 0; k < n; ++k, g += ldg)
#pragma GCC unroll 3
    for (int i = 0; i < MV; ++i) sum[i] = _mm256_add_ps(sum[i], loadRow(g + i * kLanes, kMasked && i == MV - 1, mask));
#pragma GCC unroll 3
  for (int i = 0; i < MV; ++i) {
    float* p = db + i * kLanes;
    const bool masked = kMasked && i == MV - 1;
    storeRow(p, _mm256_add_ps(loadRow(p, masked, mask), sum[i]), masked, mask);
  }
}

// Calls f(Int<NR>, first column) over n columns: tiles of 4, then one of 1-3.
template <class F>
inline void forColumnTiles(int n, F&& f) {
  int j = 0;
  for (; j + kTileCols <= n; j += kTileCols) f(Int<kTileCols>{}, j);
  switch (n - j) {
    case 3: f(Int<3>{}, j); break;
    case 2: f(Int<2>{}, j); break;
    case 1: f(Int<1>{}, j); break;
    default: break;
  }
}

template <int MV, class F>
inline void callMasked(bool masked, int row0, Mask mask, F& f) {
  if (masked) f(Int<MV>{}, std::true_type{}, row0, mask);
  else f(Int<MV>{}, std::false_type{}, row0, mask);
}

// Calls f(Int<MV>, masked, first row, mask) over the panels of `rows` (see forEachPanel).
template <class F>
inline void forPanels(int rows, F&& f) {
  const int vectors = (rows + kLanes - 1) / kLanes;
  const Mask last = firstLanes(rows - (vectors - 1) * kLanes);
  forEachPanel(rows, [&](int row0, int mv) {
    const bool masked = row0 + mv * kLanes >= vectors * kLanes && rows % kLanes != 0;
    if (mv == 3) callMasked<3>(masked, row0, last, f);
    else if (mv == 2) callMasked<2>(masked, row0, last, f);
    else callMasked<1>(masked, row0, last, f);
  });
}

template <int NR>
inline constexpr int kNarrowVectors = narrowVectors(NR);

template <int kMax, int M = 1, class C>
inline void dispatchVectors(int mv, C&& call) {
  if constexpr (M < kMax) {
    if (mv != M) return dispatchVectors<kMax, M + 1>(mv, call);
  }
  call(Int<M>{});
}

// Calls f(Int<MV>, masked, first row, mask) over blocks of at most kMax vectors of rows.
template <int kMax, class F>
inline void forNarrowBlocks(int rows, F&& f) {
  const int vectors = (rows + kLanes - 1) / kLanes;
  const Mask last = firstLanes(rows - (vectors - 1) * kLanes);
  forEachNarrowBlock(rows, kMax, [&](int row0, int mv, bool last_block) {
    const bool masked = last_block && rows % kLanes != 0;
    dispatchVectors<kMax>(mv, [&](auto m) {
      if (masked) f(m, std::true_type{}, row0, last);
      else f(m, std::false_type{}, row0, last);
    });
  });
}

// A panel of W (MV vectors of rows x depth) copied to one contiguous run, k by k, the rows past
// `rows` zero. In place, its rows of column k lie ldw floats apart: at ldw = 256, 1 KiB, so all
// of a panel's lines fall into 8 of the L1's 64 sets and evict one another.
void copyPanel(const float* w, Index ldw, int valid_rows, int width, int depth, float* panel) {
  for (int k = 0; k < depth; ++k, w += ldw, panel += width) {
    std::copy_n(w, valid_rows, panel);
    std::fill(panel + valid_rows, panel + width, 0.f);
  }
}

// The calling thread's panel buffer: a fixed one for depths up to 1024 (96 KiB per thread), so that
// a training step never allocates; a growing one would, whenever the forward's dynamic schedule
// first handed a thread a chunk (MlpAllocation.NoneForTheHumanoidPolicyFromActorToMinibatchSizes
// failed 1 run in 15 so). Deeper layers grow a buffer of their own once per thread.
float* panelBuffer(Index floats) {
  constexpr Index kFixedFloats = 3 * kLanes * 1024;
  alignas(64) thread_local float fixed[kFixedFloats];
  if (floats <= kFixedFloats) return fixed;
  thread_local std::vector<float> grown;
  if (static_cast<Index>(grown.size()) < floats) grown.resize(floats);
  return grown.data();
}

// Panels outer, column tiles inner: a panel of W (24 rows x depth, 24 KiB at depth 256), copied
// contiguous, stays in L1 while the columns of x stream past it, contiguous and prefetched. The
// other way round (the AVX-512 kernels' order, with 48 KiB of L1 on Zen 5) reads W from L2 for
// every 4 columns, which Zen 3's 32 KiB L1 and 32-byte L2 port do not keep up with.
template <Activation A>
void forwardAct(const float* w, Index ldw, int rows, int depth, const float* bias, const float* x, Index ldx, float* y,
                Index ldy, int n) {
  const int wide = n / kTileCols * kTileCols;
  if (wide > 0) {
    float* panel = panelBuffer(static_cast<Index>(3 * kLanes) * depth);
    forPanels(rows, [&](auto mv, auto masked, int row0, Mask mask) {
      constexpr int MV = decltype(mv)::value;
      copyPanel(w + row0, ldw, std::min(MV * kLanes, rows - row0), MV * kLanes, depth, panel);
      for (int j = 0; j < wide; j += kTileCols)
        forwardTile<A, MV, kTileCols, decltype(masked)::value>(panel, MV * kLanes, depth, bias ? bias + row0 : nullptr,
                                                               x + j * ldx, ldx, y + j * ldy + row0, ldy, mask);
    });
  }
  // The last 1-3 columns in narrow tiles (W read once more).
  forColumnTiles(n - wide, [&](auto nr, int j0) {
    constexpr int NR = decltype(nr)::value;
    const int j = wide + j0;
    forNarrowBlocks<kNarrowVectors<NR>>(rows, [&](auto mv, auto masked, int row0, Mask mask) {
      forwardTile<A, decltype(mv)::value, NR, decltype(masked)::value>(
          w + row0, ldw, depth, bias ? bias + row0 : nullptr, x + j * ldx, ldx, y + j * ldy + row0, ldy, mask);
    });
  });
}

// forwardAct over exactly NR = n columns on a packForward pack: each block's rows of W are one
// contiguous run (depth x MV * 8 floats).
template <Activation A, int NR>
void forwardPackedAct(const float* packed, int rows, int depth, const float* bias, const float* x, Index ldx,
                      float* y, Index ldy) {
  forNarrowBlocks<kNarrowVectors<NR>>(rows, [&](auto mv, auto masked, int row0, Mask mask) {
    constexpr int MV = decltype(mv)::value;
    forwardTile<A, MV, NR, decltype(masked)::value>(packed + static_cast<Index>(row0) * depth, MV * kLanes, depth,
                                                    bias ? bias + row0 : nullptr, x, ldx, y + row0, ldy, mask);
  });
}

template <Activation A>
void forwardPackedCols(const float* packed, int rows, int depth, const float* bias, const float* x, Index ldx,
                       float* y, Index ldy, int n) {
  switch (n) {
    case 1: return forwardPackedAct<A, 1>(packed, rows, depth, bias, x, ldx, y, ldy);
    case 2: return forwardPackedAct<A, 2>(packed, rows, depth, bias, x, ldx, y, ldy);
    case 3: return forwardPackedAct<A, 3>(packed, rows, depth, bias, x, ldx, y, ldy);
    case 4: return forwardPackedAct<A, 4>(packed, rows, depth, bias, x, ldx, y, ldy);
    default: MASA_CHECK(false, "dense::forwardPacked: " << n << " columns, expected 1 to " << kMaxPackedColumns);
  }
}

// Panels outer, as in forwardAct: the packed panel stays in L1.
template <Activation A>
void inputGradAct(const float* packed, int rows, int depth, const float* g, Index ldg, const float* y, Index ldy,
                  float* d, Index ldd, int n) {
  forPanels(rows, [&](auto mv, auto masked, int row0, Mask mask) {
    constexpr int MV = decltype(mv)::value;
    forColumnTiles(n, [&](auto nr, int j) {
      inputGradTile<A, MV, decltype(nr)::value, decltype(masked)::value>(
          packed + static_cast<Index>(row0) * depth, MV * kLanes, depth, g + j * ldg, ldg,
          y ? y + j * ldy + row0 : nullptr, ldy, d + j * ldd + row0, ldd, mask);
    });
  });
}

}  // namespace

Index packedSize(int rows, int depth) {
  return static_cast<Index>((rows + kLanes - 1) / kLanes * kLanes) * depth;
}

void pack(const float* w, Index ld, bool transpose, int rows, int depth, float* packed) {
  pack(w, ld, transpose, rows, depth, packed, 0, 1);
}

void pack(const float* w, Index ld, bool transpose, int rows, int depth, float* packed, int part, int parts) {
  MASA_CHECK(parts >= 1 && part >= 0 && part < parts, "dense::pack: part " << part << " of " << parts);
  int panel = -1;
  forEachPanel(rows, [&](int r0, int vectors) {
    const int width = vectors * kLanes;
    if (++panel % parts != part) {
      packed += static_cast<Index>(width) * depth;
      return;
    }
    const int valid = std::min(width, rows - r0);
    for (int r = 0; r < width; ++r) {
      float* dst = packed + r;
      if (r >= valid) {
        for (int k = 0; k < depth; ++k) dst[static_cast<Index>(k) * width] = 0.f;
      } else if (transpose) {  // row r of W^T is column r0 + r of W: contiguous
        const float* src = w + static_cast<Index>(r0 + r) * ld;
        for (int k = 0; k < depth; ++k) dst[static_cast<Index>(k) * width] = src[k];
      } else {
        const float* src = w + r0 + r;
        for (int k = 0; k < depth; ++k) dst[static_cast<Index>(k) * width] = src[k * ld];
      }
    }
    packed += static_cast<Index>(width) * depth;
  });
}

void packForward(const float* w, Index ldw, int rows, int depth, int n, float* packed) {
  MASA_CHECK(n >= 1 && n <= kMaxPackedColumns, "dense::packForward: " << n << " columns, expected 1 to "
                                                                      << kMaxPackedColumns);
  forEachNarrowBlock(rows, narrowVectors(n), [&](int r0, int vectors, bool) {
    const int width = vectors * kLanes, valid = std::min(width, rows - r0);
    float* dst = packed + static_cast<Index>(r0) * depth;
    for (int k = 0; k < depth; ++k, dst += width) {
      std::copy_n(w + r0 + static_cast<Index>(k) * ldw, valid, dst);
      std::fill(dst + valid, dst + width, 0.f);
    }
  });
}

void forward(const float* w, Index ldw, int rows, int depth, const float* bias, Activation act, const float* x,
             Index ldx, float* y, Index ldy, int n) {
  switch (act) {
    case Activation::kIdentity:
      return forwardAct<Activation::kIdentity>(w, ldw, rows, depth, bias, x, ldx, y, ldy, n);
    case Activation::kElu: return forwardAct<Activation::kElu>(w, ldw, rows, depth, bias, x, ldx, y, ldy, n);
    case Activation::kTanh: return forwardAct<Activation::kTanh>(w, ldw, rows, depth, bias, x, ldx, y, ldy, n);
    case Activation::kRelu: return forwardAct<Activation::kRelu>(w, ldw, rows, depth, bias, x, ldx, y, ldy, n);
  }
}

void forwardPacked(const float* packed, int rows, int depth, const float* bias, Activation act, const float* x,
                   Index ldx, float* y, Index ldy, int n) {
  switch (act) {
    case Activation::kIdentity:
      return forwardPackedCols<Activation::kIdentity>(packed, rows, depth, bias, x, ldx, y, ldy, n);
    case Activation::kElu: return forwardPackedCols<Activation::kElu>(packed, rows, depth, bias, x, ldx, y, ldy, n);
    case Activation::kTanh: return forwardPackedCols<Activation::kTanh>(packed, rows, depth, bias, x, ldx, y, ldy, n);
    case Activation::kRelu: return forwardPackedCols<Activation::kRelu>(packed, rows, depth, bias, x, ldx, y, ldy, n);
  }
}

void inputGrad(const float* packed, int rows, int depth, const float* g, Index ldg, Activation act, const float* y,
               Index ldy, float* d, Index ldd, int n) {
  switch (act) {
    case Activation::kIdentity:
      return inputGradAct<Activation::kIdentity>(packed, rows, depth, g, ldg, nullptr, ldy, d, ldd, n);
    case Activation::kElu: return inputGradAct<Activation::kElu>(packed, rows, depth, g, ldg, y, ldy, d, ldd, n);
    case Activation::kTanh: return inputGradAct<Activation::kTanh>(packed, rows, depth, g, ldg, y, ldy, d, ldd, n);
    case Activation::kRelu: return inputGradAct<Activation::kRelu>(packed, rows, depth, g, ldg, y, ldy, d, ldd, n);
  }
}

void weightGrad(int rows, int cols, int n, const float* g, Index ldg, const float* x, Index ldx, float* dw,
                float* db) {
  for (int k0 = 0; k0 < n; k0 += kDepthBlock) {
    const int kc = std::min(kDepthBlock, n - k0);
    const float* gk = g + k0 * ldg;
    const float* xk = x + k0 * ldx;
    for (int k = 0; k < kc; ++k) _mm_prefetch(reinterpret_cast<const char*>(xk + k * ldx), _MM_HINT_T0);
    if (db)
      forPanels(rows, [&](auto mv, auto masked, int row0, Mask mask) {
        rowSumTile<decltype(mv)::value, decltype(masked)::value>(kc, gk + row0, ldg, db + row0, mask);
      });
    // Panels of g outer (24 rows x kc columns stay in L1), column tiles of x inner.
    forPanels(rows, [&](auto mv, auto masked, int row0, Mask mask) {
      forColumnTiles(cols, [&](auto nr, int j) {
        weightGradTile<decltype(mv)::value, decltype(nr)::value, decltype(masked)::value>(
            kc, gk + row0, ldg, xk + j, ldx, dw + static_cast<Index>(j) * rows + row0, rows, mask);
      });
    });
  }
}

}  // namespace masa::nn::dense

#endif  // MASA_DENSE_AVX2
