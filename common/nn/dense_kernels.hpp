// Float kernels for the three products of a dense layer, with the elementwise work fused in, on
// AVX-512 (dense_kernels.cpp) or, on CPUs without it, AVX2 + FMA (dense_kernels_avx2.cpp).
//
// A layer's training step is Y = f(W X + b) forward, then dX = (W^T G) .* f'(Y_prev) and
// dW += G X^T, db += G 1 backward, all column-major (features x batch). Each kernel keeps a
// tile of its result in registers (AVX-512: 48 x 8 in 24 of the 32 zmm registers; AVX2: 24 x 4 in
// 12 of the 16 ymm registers) and applies the bias, activation or activation derivative to the
// tile before storing it, so no elementwise pass goes over memory. The batch operand is read in
// place, which saves a packing pass over the large operand; forward reads W in place too (its
// columns are the rows the tile needs), and only W^T for the input gradient is packed, once per
// step. Forward over 1-4 columns (the actors' and the robot runner's inference) keeps a narrow
// tile of many vectors x 1-4 columns instead, so that W is read once; which tile computes a
// column changes no bit of its result.
//
// f' is computed from Y (ELU: min(y,0)+1; tanh: 1-y^2; ReLU: y>0), so z = Wx+b is never stored.
// The caller splits the batch over threads: every function is single-threaded and allocates
// nothing. The kernels exist where the compiler targets AVX-512F or AVX2 with FMA (kAvailable);
// elsewhere they throw, and the MLP uses GemmWorkspace instead. The two instruction sets sum
// each element in the same order (over k, from zero) but their tiles, and so their packed
// layouts, differ: kLanes says which one this build has.
#pragma once

#include <cstddef>

#include "common/nn/activation.hpp"

namespace masa::nn::dense {

#if defined(__AVX512F__)
#define MASA_DENSE_AVX512 1
inline constexpr bool kAvailable = true;
inline constexpr int kLanes = 16;  // floats in a vector register
#elif defined(__AVX2__) && defined(__FMA__)
#define MASA_DENSE_AVX2 1
inline constexpr bool kAvailable = true;
inline constexpr int kLanes = 8;
#else
inline constexpr bool kAvailable = false;
inline constexpr int kLanes = 16;  // (the layout functions' geometry; the products throw)
#endif

using Index = std::ptrdiff_t;

// Floats needed to pack a rows x depth operand (rows rounded up to a multiple of kLanes).
Index packedSize(int rows, int depth);

// Packs op(W) (rows x depth) into panels of 3 (or 2 or 1) vectors of kLanes rows, each stored as depth
// consecutive groups of its rows, zero-padded. W is column-major with leading dimension ld;
// op(W) = W when !transpose (W is rows x depth), W^T when transpose (W is depth x rows).
// `packed` holds packedSize(rows, depth) floats.
void pack(const float* w, Index ld, bool transpose, int rows, int depth, float* packed);
// The same layout, written only for panels p with p % parts == part: `parts` threads, each with
// its own part, write together exactly what one pack() writes.
void pack(const float* w, Index ld, bool transpose, int rows, int depth, float* packed, int part, int parts);

// y = f(W x + bias) for n columns. W: rows x depth (ldw), read in place; x: depth x n (ldx);
// y: rows x n (ldy); bias: rows values or null. Writes only the rows < `rows` of y.
void forward(const float* w, Index ldw, int rows, int depth, const float* bias, Activation act, const float* x,
             Index ldx, float* y, Index ldy, int n);

// Inference on parameters that do not change (a deployed policy) can read W from a copy packed for
// its column count: forward over n <= 4 columns splits the rows into blocks of many vectors, and
// on W in place each block reads a strided part of every column of W; packed, it reads one
// contiguous run, which the hardware prefetchers follow (2 columns of a 400-row layer: 0.041 ->
// 0.022 ns per weight on Zen 5, bench_mlp NarrowForward).
inline constexpr int kMaxPackedColumns = 4;
// Packs W (rows x depth, ldw) for forwardPacked over n (1-4) columns, in packedSize(rows, depth)
// floats, padded with zeros.
void packForward(const float* w, Index ldw, int rows, int depth, int n, float* packed);
// forward() over exactly n (1-4) columns, W from packForward(..., n, ...): bit-identical to it.
void forwardPacked(const float* packed, int rows, int depth, const float* bias, Activation act, const float* x,
                   Index ldx, float* y, Index ldy, int n);

// d = (P g) .* f'(y) for n columns, f' of `act` written in terms of y (y unused for identity).
// P: packed rows x depth (W^T); g: depth x n (ldg); y, d: rows x n (ldy, ldd). d may not alias g.
void inputGrad(const float* packed, int rows, int depth, const float* g, Index ldg, Activation act, const float* y,
               Index ldy, float* d, Index ldd, int n);

// dw += g x^T and db += row sums of g, over n columns. g: rows x n (ldg); x: cols x n (ldx);
// dw: rows x cols with leading dimension rows; db: rows values or null.
void weightGrad(int rows, int cols, int n, const float* g, Index ldg, const float* x, Index ldx, float* dw,
                float* db);

}  // namespace masa::nn::dense
