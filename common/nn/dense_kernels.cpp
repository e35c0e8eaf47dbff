// Register-tile kernels of dense_kernels.hpp. Every kernel walks its result in tiles of up to
// 3 vectors (48 rows) x 8 columns; the tile loop keeps one small operand block in L1 (8 columns
// of the batch, or 8 rows of x^T) and streams the weights (or g) from L2. Forward over 1-4
// columns (inference) uses narrow tiles of up to 28 vectors instead (forNarrowBlocks), on W in
// place or on a copy packed block by block (packForward, forwardPacked).

// GCC 12's AVX-512 headers implement _mm512_min_ps and friends with an undefined pass-through
// vector under an all-ones mask, which -Wuninitialized reports at every inlined use (also inside
// Eigen's pexp): set before any include so that it covers the headers' code too.
#pragma GCC diagnostic ignored "-Wuninitialized"

#include "common/nn/dense_kernels.hpp"

// An AVX2 build has its own tiles and layouts (dense_kernels_avx2.cpp).
#if !defined(MASA_DENSE_AVX2)

#include <algorithm>
#include <type_traits>

#include "common/core/check.hpp"
#include "common/core/types.hpp"

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace masa::nn::dense {

namespace {

// Splits ceil(rows / 16) vectors into panels of 3 vectors, with 2-vector panels for a remainder
// (v = 3q + 1 as 3(q-1) + 2 + 2): a 2 x 8 tile still hides the FMA latency, a 1 x 8 one barely.
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

// Forward over few columns (single-sample inference, the robot runner's N agents, a batch's last
// columns): a 3-vector panel would keep only 3 x NR FMA chains in flight, too few to hide the FMA
// latency on two ports, and would stream W from L2 once per 48 rows. A narrow tile covers up to
// narrowVectors(NR) vectors of rows (all 400 rows of a humanoid layer in one block when NR = 1)
// in at most 28 + NR zmm registers, so W is read once.
constexpr int narrowVectors(int nr) { return nr == 1 ? 28 : nr == 2 ? 14 : nr == 3 ? 9 : 6; }

// Splits ceil(rows / 16) vectors into blocks of at most max_vectors, sized evenly (25 vectors with
// 9 at most: 9, 8, 8). f(first row, vectors, last block).
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

#if defined(__AVX512F__)
namespace {

constexpr int kTileCols = 8;
// Batch columns per weight-gradient block: g's and x's blocks (at most 400 x 128 floats each)
// stay in L2 while every tile of dw passes over them.
constexpr int kDepthBlock = 128;

template <int N>
using Int = std::integral_constant<int, N>;

__mmask16 firstLanes(int valid) { return valid >= kLanes ? __mmask16(0xFFFF) : __mmask16((1u << valid) - 1u); }

// `masked` is a constant once the tile loops are unrolled.
inline __m512 loadRow(const float* p, bool masked, __mmask16 mask) {
  return masked ? _mm512_maskz_loadu_ps(mask, p) : _mm512_loadu_ps(p);
}

inline void storeRow(float* p, __m512 v, bool masked, __mmask16 mask) {
  if (masked)
    _mm512_mask_storeu_ps(p, mask, v);
  else
    _mm512_storeu_ps(p, v);
}

template <Activation A>
inline __m512 activation(__m512 z) {
  const __m512 zero = _mm512_setzero_ps();
  if constexpr (A == Activation::kIdentity) {
    return z;
  } else if constexpr (A == Activation::kRelu) {
    return _mm512_max_ps(z, zero);
  } else if constexpr (A == Activation::kElu) {
    // As in activation.cpp: y == z exactly for z > 0.
    const __m512 e = _mm512_sub_ps(Eigen::internal::pexp(_mm512_min_ps(z, zero)), _mm512_set1_ps(1.f));
    return _mm512_add_ps(_mm512_max_ps(z, zero), e);
  } else {
    return Eigen::internal::ptanh(z);
  }
}

// f'(z) from y = f(z).
template <Activation A>
inline __m512 derivative(__m512 y) {
  const __m512 one = _mm512_set1_ps(1.f);
  if constexpr (A == Activation::kRelu) {
    return _mm512_maskz_mov_ps(_mm512_cmp_ps_mask(y, _mm512_setzero_ps(), _CMP_GT_OQ), one);
  } else if constexpr (A == Activation::kElu) {
    return _mm512_add_ps(_mm512_min_ps(y, _mm512_setzero_ps()), one);
  } else {
    return _mm512_sub_ps(one, _mm512_mul_ps(y, y));
  }
}

// acc = rows of a (MV vectors, the last one masked when kMasked; column k at a + k * lda) times
// columns [0, NR) of b (depth x NR, ldb).
template <int MV, int NR, bool kMasked>
inline void panelTimesColumns(const float* __restrict a, Index lda, int depth, const float* __restrict b, Index ldb,
                              __mmask16 mask, __m512 (&acc)[MV][NR]) {
#pragma GCC unroll 8
  for (int j = 0; j < NR; ++j)
#pragma GCC unroll 32
    for (int i = 0; i < MV; ++i) acc[i][j] = _mm512_setzero_ps();
  const float* col[NR];
#pragma GCC unroll 8
  for (int j = 0; j < NR; ++j) col[j] = b + j * ldb;
  if constexpr (MV > 3) {
    // Narrow tiles (up to 28 vectors x 1-4 columns): the NR broadcasts first, then one row of W
    // at a time, used by all NR columns at once: MV x NR accumulators + NR + 1 registers. The
    // empty asm keeps the row in a register; left alone, GCC folds the load into each of the NR
    // FMAs, NR loads per vector of W, and the loop becomes load-bound.
    for (int k = 0; k < depth; ++k, a += lda) {
      __m512 bj[NR];
#pragma GCC unroll 8
      for (int j = 0; j < NR; ++j) bj[j] = _mm512_set1_ps(col[j][k]);
#pragma GCC unroll 32
      for (int i = 0; i < MV; ++i) {
        __m512 av = loadRow(a + i * kLanes, kMasked && i == MV - 1, mask);
        if constexpr (NR > 1) __asm__("" : "+v"(av));
#pragma GCC unroll 8
        for (int j = 0; j < NR; ++j) acc[i][j] = _mm512_fmadd_ps(av, bj[j], acc[i][j]);
      }
    }
  } else {
    for (int k = 0; k < depth; ++k, a += lda) {
      __m512 av[MV];
#pragma GCC unroll 3
      for (int i = 0; i < MV; ++i) av[i] = loadRow(a + i * kLanes, kMasked && i == MV - 1, mask);
#pragma GCC unroll 8
      for (int j = 0; j < NR; ++j) {
        const __m512 bj = _mm512_set1_ps(col[j][k]);
#pragma GCC unroll 3
        for (int i = 0; i < MV; ++i) acc[i][j] = _mm512_fmadd_ps(av[i], bj, acc[i][j]);
      }
    }
  }
}

template <Activation A, int MV, int NR, bool kMasked>
void forwardTile(const float* a, Index lda, int depth, const float* bias, const float* x, Index ldx, float* y,
                 Index ldy, __mmask16 mask) {
  __m512 acc[MV][NR];
  panelTimesColumns<MV, NR, kMasked>(a, lda, depth, x, ldx, mask, acc);
  if constexpr (MV > 3) {
    // Narrow-column tiles of up to 28 vectors: store z = acc + bias, then activate it in a loop
    // (in L1; one instance of the activation's code instead of MV x NR inlined copies).
#pragma GCC unroll 8
    for (int j = 0; j < NR; ++j)
#pragma GCC unroll 32
      for (int i = 0; i < MV; ++i) {
        const bool masked = kMasked && i == MV - 1;
        const __m512 b = bias ? loadRow(bias + i * kLanes, masked, mask) : _mm512_setzero_ps();
        storeRow(y + j * ldy + i * kLanes, _mm512_add_ps(acc[i][j], b), masked, mask);
      }
    if constexpr (A != Activation::kIdentity)
      for (int j = 0; j < NR; ++j)
        for (int i = 0; i < MV; ++i) {
          float* p = y + j * ldy + i * kLanes;
          const bool masked = kMasked && i == MV - 1;
          storeRow(p, activation<A>(loadRow(p, masked, mask)), masked, mask);
        }
  } else {
    __m512 b[MV];
#pragma GCC unroll 3
    for (int i = 0; i < MV; ++i)
      b[i] = bias ? loadRow(bias + i * kLanes, kMasked && i == MV - 1, mask) : _mm512_setzero_ps();
#pragma GCC unroll 8
    for (int j = 0; j < NR; ++j)
#pragma GCC unroll 3
      for (int i = 0; i < MV; ++i)
        storeRow(y + j * ldy + i * kLanes, activation<A>(_mm512_add_ps(acc[i][j], b[i])), kMasked && i == MV - 1,
                 mask);
  }
}

template <Activation A, int MV, int NR, bool kMasked>
void inputGradTile(const float* a, Index lda, int depth, const float* g, Index ldg, const float* y, Index ldy,
                   float* d, Index ldd, __mmask16 mask) {
  __m512 acc[MV][NR];
  panelTimesColumns<MV, NR, kMasked>(a, lda, depth, g, ldg, mask, acc);
#pragma GCC unroll 8
  for (int j = 0; j < NR; ++j)
#pragma GCC unroll 3
    for (int i = 0; i < MV; ++i) {
      __m512 v = acc[i][j];
      if constexpr (A != Activation::kIdentity)
        v = _mm512_mul_ps(v, derivative<A>(loadRow(y + j * ldy + i * kLanes, kMasked && i == MV - 1, mask)));
      storeRow(d + j * ldd + i * kLanes, v, kMasked && i == MV - 1, mask);
    }
}

// dw tile (MV vectors of rows x NR columns) += g x^T over n batch columns; with kRowSum also
// db += row sums of g (the tile of the first NR columns carries them: g is in registers anyway).
template <int MV, int NR, bool kMasked, bool kRowSum>
void weightGradTile(int n, const float* __restrict g, Index ldg, const float* __restrict x, Index ldx,
                    float* __restrict dw, Index lddw, float* __restrict db, __mmask16 mask) {
  __m512 acc[MV][NR], sum[MV];
#pragma GCC unroll 3
  for (int i = 0; i < MV; ++i) {
    sum[i] = _mm512_setzero_ps();
#pragma GCC unroll 8
    for (int j = 0; j < NR; ++j) acc[i][j] = _mm512_setzero_ps();
  }
  for (int k = 0; k < n; ++k, g += ldg, x += ldx) {
    // The next cache line of this column of x is the one the tile two to the right needs: its
    // columns are scattered (one line each), so the hardware prefetcher does not bring them.
    _mm_prefetch(reinterpret_cast<const char*>(x + kLanes), _MM_HINT_T0);
    __m512 av[MV];
#pragma GCC unroll 3
    for (int i = 0; i < MV; ++i) {
      av[i] = loadRow(g + i * kLanes, kMasked && i == MV - 1, mask);
      if constexpr (kRowSum) sum[i] = _mm512_add_ps(sum[i], av[i]);
    }
#pragma GCC unroll 8
    for (int j = 0; j < NR; ++j) {
      const __m512 xj = _mm512_set1_ps(x[j]);
#pragma GCC unroll 3
      for (int i = 0; i < MV; ++i) acc[i][j] = _mm512_fmadd_ps(av[i], xj, acc[i][j]);
    }
  }
#pragma GCC unroll 8
  for (int j = 0; j < NR; ++j)
#pragma GCC unroll 3
    for (int i = 0; i < MV; ++i) {
      float* p = dw + j * lddw + i * kLanes;
      const bool masked = kMasked && i == MV - 1;
      storeRow(p, _mm512_add_ps(loadRow(p, masked, mask), acc[i][j]), masked, mask);
    }
  if constexpr (kRowSum) {
#pragma GCC unroll 3
    for (int i = 0; i < MV; ++i) {
      float* p = db + i * kLanes;
      const bool masked = kMasked && i == MV - 1;
      storeRow(p, _mm512_add_ps(loadRow(p, masked, mask), sum[i]), masked, mask);
    }
  }
}

// Calls f(Int<NR>, first column) over n columns: tiles of 8, then one of 4 and one of 1-3 (a
// single tile of 3 rather than 2 + 1: a narrow forward tile then reads W once, not twice).
template <class F>
inline void forColumnTiles(int n, F&& f) {
  int j = 0;
  for (; j + kTileCols <= n; j += kTileCols) f(Int<kTileCols>{}, j);
  if (n - j >= 4) f(Int<4>{}, j), j += 4;
  switch (n - j) {
    case 3: f(Int<3>{}, j); break;
    case 2: f(Int<2>{}, j); break;
    case 1: f(Int<1>{}, j); break;
    default: break;
  }
}

// Calls f(Int<MV>, masked, first row, mask) over the panels of `rows` (see forEachPanel).
template <class F>
inline void forPanels(int rows, F&& f) {
  const int vectors = (rows + kLanes - 1) / kLanes;
  const __mmask16 last = firstLanes(rows - (vectors - 1) * kLanes);
  forEachPanel(rows, [&](int row0, int mv) {
    const bool masked = row0 + mv * kLanes >= vectors * kLanes && rows % kLanes != 0;
    const __mmask16 mask = masked ? last : __mmask16(0xFFFF);
    if (mv == 3) {
      if (masked) f(Int<3>{}, std::true_type{}, row0, mask);
      else f(Int<3>{}, std::false_type{}, row0, mask);
    } else if (mv == 2) {
      if (masked) f(Int<2>{}, std::true_type{}, row0, mask);
      else f(Int<2>{}, std::false_type{}, row0, mask);
    } else {
      if (masked) f(Int<1>{}, std::true_type{}, row0, mask);
      else f(Int<1>{}, std::false_type{}, row0, mask);
    }
  });
}

// Narrow tiles (see narrowVectors) sum each result element over k in order from zero, exactly as
// the 48 x 8 tile does: which tile computes a column changes no bit of it.
template <int NR>
inline constexpr int kNarrowVectors = narrowVectors(NR);

template <int kMax, int M = 1, class C>
inline void dispatchVectors(int mv, C&& call) {
  if constexpr (M < kMax) {
    if (mv != M) return dispatchVectors<kMax, M + 1>(mv, call);
  }
  call(Int<M>{});
}

// Calls f(Int<MV>, masked, first row, mask) over blocks of at most kMax vectors of rows, sized
// evenly (25 vectors with kMax = 9: 9, 8, 8).
template <int kMax, class F>
inline void forNarrowBlocks(int rows, F&& f) {
  const int vectors = (rows + kLanes - 1) / kLanes;
  const __mmask16 last = firstLanes(rows - (vectors - 1) * kLanes);
  forEachNarrowBlock(rows, kMax, [&](int row0, int mv, bool last_block) {
    const bool masked = last_block && rows % kLanes != 0;
    const __mmask16 mask = masked ? last : __mmask16(0xFFFF);
    dispatchVectors<kMax>(mv, [&](auto m) {
      if (masked) f(m, std::true_type{}, row0, mask);
      else f(m, std::false_type{}, row0, mask);
    });
  });
}

template <Activation A>
void forwardAct(const float* w, Index ldw, int rows, int depth, const float* bias, const float* x, Index ldx, float* y,
                Index ldy, int n) {
  forColumnTiles(n, [&](auto nr, int j) {
    constexpr int NR = decltype(nr)::value;
    auto tile = [&](auto mv, auto masked, int row0, __mmask16 mask) {
      forwardTile<A, decltype(mv)::value, NR, decltype(masked)::value>(
          w + row0, ldw, depth, bias ? bias + row0 : nullptr, x + j * ldx, ldx, y + j * ldy + row0, ldy, mask);
    };
    if constexpr (NR <= 4)
      forNarrowBlocks<kNarrowVectors<NR>>(rows, tile);
    else
      forPanels(rows, tile);
  });
}

// forwardAct over exactly NR = n columns on a packForward pack: each block's rows of W are one
// contiguous run (depth x MV * 16 floats), not MV * 16 floats in every column of W.
template <Activation A, int NR>
void forwardPackedAct(const float* packed, int rows, int depth, const float* bias, const float* x, Index ldx,
                      float* y, Index ldy) {
  forNarrowBlocks<kNarrowVectors<NR>>(rows, [&](auto mv, auto masked, int row0, __mmask16 mask) {
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

template <Activation A>
void inputGradAct(const float* packed, int rows, int depth, const float* g, Index ldg, const float* y, Index ldy,
                  float* d, Index ldd, int n) {
  forColumnTiles(n, [&](auto nr, int j) {
    forPanels(rows, [&](auto mv, auto masked, int row0, __mmask16 mask) {
      constexpr int MV = decltype(mv)::value;
      inputGradTile<A, MV, decltype(nr)::value, decltype(masked)::value>(
          packed + static_cast<Index>(row0) * depth, MV * kLanes, depth, g + j * ldg, ldg,
          y ? y + j * ldy + row0 : nullptr, ldy, d + j * ldd + row0, ldd, mask);
    });
  });
}

}  // namespace

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
    forColumnTiles(cols, [&](auto nr, int j) {
      forPanels(rows, [&](auto mv, auto masked, int row0, __mmask16 mask) {
        constexpr int MV = decltype(mv)::value, NR = decltype(nr)::value;
        constexpr bool kMasked = decltype(masked)::value;
        float* tile = dw + static_cast<Index>(j) * rows + row0;
        if (db && j == 0)
          weightGradTile<MV, NR, kMasked, true>(kc, gk + row0, ldg, xk + j, ldx, tile, rows, db + row0, mask);
        else
          weightGradTile<MV, NR, kMasked, false>(kc, gk + row0, ldg, xk + j, ldx, tile, rows, nullptr, mask);
      });
    });
  }
}

#else  // neither AVX-512 nor AVX2: kAvailable is false and the MLP never calls these

void forward(const float*, Index, int, int, const float*, Activation, const float*, Index, float*, Index, int) {
  MASA_CHECK(false, "dense::forward needs AVX-512");
}
void forwardPacked(const float*, int, int, const float*, Activation, const float*, Index, float*, Index, int) {
  MASA_CHECK(false, "dense::forwardPacked needs AVX-512");
}
void inputGrad(const float*, int, int, const float*, Index, Activation, const float*, Index, float*, Index, int) {
  MASA_CHECK(false, "dense::inputGrad needs AVX-512");
}
void weightGrad(int, int, int, const float*, Index, const float*, Index, float*, float*) {
  MASA_CHECK(false, "dense::weightGrad needs AVX-512");
}

#endif

}  // namespace masa::nn::dense

#endif  // !MASA_DENSE_AVX2
