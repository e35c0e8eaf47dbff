// The dense-layer kernels (AVX-512, or AVX2 on CPUs without it) against plain Eigen products, over
// shapes that exercise every panel width (3, 2 and 1 vectors, masked last vector), every column
// tile, strided operands and all activations; the packed layouts of each instruction set; and the
// fused MLP engine against the double-precision generic one.
#include <gtest/gtest.h>
#include <omp.h>

#include <memory>
#include <tuple>
#include <utility>
#include <vector>

#include "common/nn/dense_kernels.hpp"
#include "common/nn/mlp.hpp"

namespace masa::nn {
namespace {

using Eigen::Index;

Mat<double> reference(const Mat<float>& m) { return m.cast<double>(); }

Mat<double> activated(Activation a, const Mat<double>& z) {
  switch (a) {
    case Activation::kIdentity: return z;
    case Activation::kElu: return z.unaryExpr([](double v) { return v > 0 ? v : std::expm1(v); });
    case Activation::kTanh: return z.array().tanh().matrix();
    case Activation::kRelu: return z.cwiseMax(0.0);
  }
  return z;
}

Mat<double> derivativeFromY(Activation a, const Mat<double>& y) {
  switch (a) {
    case Activation::kIdentity: return Mat<double>::Ones(y.rows(), y.cols());
    case Activation::kElu: return y.unaryExpr([](double v) { return v > 0 ? 1.0 : v + 1.0; });
    case Activation::kTanh: return (1.0 - y.array().square()).matrix();
    case Activation::kRelu: return y.unaryExpr([](double v) { return v > 0 ? 1.0 : 0.0; });
  }
  return y;
}

// (rows, depth, n): rows cover 1, 2 and 3-vector panels with and without a partial last vector;
// n covers every column tile width.
using Shape = std::tuple<int, int, int>;

class DenseKernels : public ::testing::TestWithParam<Shape> {
 protected:
  void SetUp() override {
    if (!dense::kAvailable) GTEST_SKIP() << "built without AVX-512 or AVX2";
  }
};

TEST_P(DenseKernels, ForwardMatchesEigenForEveryActivationAndLeavesPaddingAlone) {
  const auto [rows, depth, n] = GetParam();
  const Mat<float> w_store = Mat<float>::Random(rows + 3, depth);  // ldw > rows
  const Mat<float> x_store = Mat<float>::Random(depth + 5, n);
  const Mat<float> bias = Mat<float>::Random(rows, 1);
  const Mat<double> z = (reference(w_store.topRows(rows)) * reference(x_store.topRows(depth))).colwise() +
                        reference(bias).col(0);
  for (Activation a : {Activation::kIdentity, Activation::kElu, Activation::kTanh, Activation::kRelu}) {
    Mat<float> y_store = Mat<float>::Constant(rows + 7, n, 42.f);
    dense::forward(w_store.data(), w_store.rows(), rows, depth, bias.data(), a, x_store.data(), x_store.rows(),
                   y_store.data(), y_store.rows(), n);
    const double err = (reference(y_store.topRows(rows)) - activated(a, z)).cwiseAbs().maxCoeff();
    EXPECT_LT(err, 2e-6 * depth + 1e-6) << activationName(a);
    EXPECT_TRUE((y_store.bottomRows(7).array() == 42.f).all()) << activationName(a) << ": rows past `rows` written";
  }
  // Without bias.
  Mat<float> y(rows, n);
  dense::forward(w_store.data(), w_store.rows(), rows, depth, nullptr, Activation::kIdentity, x_store.data(),
                 x_store.rows(), y.data(), rows, n);
  const Mat<double> wx = reference(w_store.topRows(rows)) * reference(x_store.topRows(depth));
  EXPECT_LT((reference(y) - wx).cwiseAbs().maxCoeff(), 2e-6 * depth + 1e-6);
}

TEST_P(DenseKernels, InputGradMatchesEigenTimesTheDerivativeFromY) {
  // d (rows x n) = W^T g .* f'(y), with W stored depth x rows (a layer of `depth` outputs).
  const auto [rows, depth, n] = GetParam();
  const Mat<float> w = Mat<float>::Random(depth, rows);
  std::vector<float, Eigen::aligned_allocator<float>> packed(dense::packedSize(rows, depth));
  dense::pack(w.data(), w.rows(), true, rows, depth, packed.data());
  const Mat<float> g_store = Mat<float>::Random(depth + 2, n);
  const Mat<float> y_store = Mat<float>::Random(rows + 4, n);
  const Mat<double> wtg = reference(w).transpose() * reference(g_store.topRows(depth));
  for (Activation a : {Activation::kIdentity, Activation::kElu, Activation::kTanh, Activation::kRelu}) {
    Mat<float> d_store = Mat<float>::Constant(rows + 1, n, -3.f);
    dense::inputGrad(packed.data(), rows, depth, g_store.data(), g_store.rows(), a, y_store.data(), y_store.rows(),
                     d_store.data(), d_store.rows(), n);
    const Mat<double> expected = (wtg.array() * derivativeFromY(a, reference(y_store.topRows(rows))).array()).matrix();
    EXPECT_LT((reference(d_store.topRows(rows)) - expected).cwiseAbs().maxCoeff(), 2e-6 * depth + 1e-6)
        << activationName(a);
    EXPECT_TRUE((d_store.bottomRows(1).array() == -3.f).all()) << activationName(a);
  }
}

TEST_P(DenseKernels, WeightGradAccumulatesProductAndRowSums) {
  // dw (rows x cols) += g x^T over n columns, db += g 1; here `depth` plays cols.
  const auto [rows, cols, n] = GetParam();
  const Mat<float> g_store = Mat<float>::Random(rows + 3, n);
  const Mat<float> x_store = Mat<float>::Random(cols + 1, n);
  const Mat<float> dw0 = Mat<float>::Random(rows, cols);
  const Mat<float> db0 = Mat<float>::Random(rows, 1);
  Mat<float> dw = dw0, db = db0;
  dense::weightGrad(rows, cols, n, g_store.data(), g_store.rows(), x_store.data(), x_store.rows(), dw.data(),
                    db.data());
  const Mat<double> g = reference(g_store.topRows(rows));
  const Mat<double> expected_w = reference(dw0) + g * reference(x_store.topRows(cols)).transpose();
  const Mat<double> expected_b = reference(db0) + g.rowwise().sum();
  EXPECT_LT((reference(dw) - expected_w).cwiseAbs().maxCoeff(), 2e-6 * n + 1e-6);
  EXPECT_LT((reference(db) - expected_b).cwiseAbs().maxCoeff(), 2e-6 * n + 1e-6);
  // Without db.
  Mat<float> dw2 = Mat<float>::Zero(rows, cols);
  dense::weightGrad(rows, cols, n, g_store.data(), g_store.rows(), x_store.data(), x_store.rows(), dw2.data(), nullptr);
  EXPECT_LT((reference(dw2) - g * reference(x_store.topRows(cols)).transpose()).cwiseAbs().maxCoeff(), 2e-6 * n + 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Shapes, DenseKernels,
                         ::testing::Values(Shape{1, 1, 1}, Shape{5, 3, 2}, Shape{16, 7, 8}, Shape{21, 100, 15},
                                           Shape{33, 4, 9}, Shape{48, 16, 17}, Shape{64, 5, 3}, Shape{100, 200, 31},
                                           Shape{200, 74, 129}, Shape{400, 21, 7}, Shape{74, 400, 300},
                                           // narrow forward tiles: 25 vectors in one block (n = 1),
                                           // 29 vectors in three masked blocks (n = 2), 8 + 4 + 1
                                           Shape{400, 30, 1}, Shape{450, 9, 2}, Shape{300, 11, 13}));

// Which tile computes a column must not change a bit of it: the robot runner infers one sample (or
// its N agents) and has to act exactly as the policy did in a batch during evaluation.
TEST(DenseKernelsForward, AColumnIsBitIdenticalWhateverTileComputesIt) {
  if (!dense::kAvailable) GTEST_SKIP() << "built without AVX-512 or AVX2";
  for (const int rows : {21, 100, 400, 450}) {
    const int depth = 37, n = 19;  // 8 + 8 + 3 columns in one call
    const Mat<float> w = Mat<float>::Random(rows, depth);
    const Mat<float> bias = Mat<float>::Random(rows, 1);
    const Mat<float> x = Mat<float>::Random(depth, n);
    for (const Activation a : {Activation::kIdentity, Activation::kElu, Activation::kTanh, Activation::kRelu}) {
      Mat<float> batch(rows, n);
      dense::forward(w.data(), rows, rows, depth, bias.data(), a, x.data(), depth, batch.data(), rows, n);
      for (int width = 1; width <= 4; ++width)
        for (int j0 = 0; j0 + width <= n; j0 += width) {
          Mat<float> part(rows, width);
          dense::forward(w.data(), rows, rows, depth, bias.data(), a, x.data() + j0 * depth, depth, part.data(), rows,
                         width);
          EXPECT_TRUE(part == batch.middleCols(j0, width))
              << "rows " << rows << ", columns " << j0 << ".." << j0 + width - 1 << " alone, " << activationName(a);
        }
    }
  }
}

// The robot runner's path: W packed for its column count gives the bits of W read in place, for
// 1-4 columns, blocks of every size (450 rows: two blocks even for one column), strided x and y,
// every activation, and rows of y beyond `rows` left alone.
TEST(DenseKernelsForward, PackedWeightsGiveTheBitsOfWInPlace) {
  if (!dense::kAvailable) GTEST_SKIP() << "built without AVX-512 or AVX2";
  for (const int rows : {7, 21, 100, 400, 450}) {
    const int depth = 37, ldx = depth + 3, ldy = rows + 5;
    const Mat<float> w = Mat<float>::Random(rows, depth);
    const Mat<float> bias = Mat<float>::Random(rows, 1);
    const Mat<float> x = Mat<float>::Random(ldx, 4);
    for (int n = 1; n <= dense::kMaxPackedColumns; ++n) {
      std::vector<float> packed(dense::packedSize(rows, depth));
      dense::packForward(w.data(), rows, rows, depth, n, packed.data());
      for (const Activation a : {Activation::kIdentity, Activation::kElu, Activation::kTanh, Activation::kRelu}) {
        Mat<float> in_place = Mat<float>::Constant(ldy, n, 7.f), from_pack = Mat<float>::Constant(ldy, n, 7.f);
        dense::forward(w.data(), rows, rows, depth, bias.data(), a, x.data(), ldx, in_place.data(), ldy, n);
        dense::forwardPacked(packed.data(), rows, depth, bias.data(), a, x.data(), ldx, from_pack.data(), ldy, n);
        EXPECT_TRUE(from_pack == in_place) << rows << " rows, " << n << " columns, " << activationName(a);
        EXPECT_TRUE((from_pack.bottomRows(ldy - rows).array() == 7.f).all()) << "wrote below row " << rows;
      }
    }
  }
}

// AVX-512's narrow tiles: at most 28, 14, 9 and 6 vectors of 16 rows for 1-4 columns.
TEST(DenseKernelsPack, ForwardPackHoldsEachRowBlockContiguouslyZeroPadded) {
  if (!dense::kAvailable || dense::kLanes != 16) GTEST_SKIP() << "AVX-512's layout (this build: AVX2 or none)";
  const int depth = 3;
  {  // 70 rows = 5 vectors: one block for 4 columns (at most 6 vectors), 10 rows of zeros
    const Mat<float> w = Mat<float>::Random(70, depth);
    std::vector<float> packed(dense::packedSize(70, depth), -1.f);
    dense::packForward(w.data(), 70, 70, depth, 4, packed.data());
    for (int k = 0; k < depth; ++k)
      for (int r = 0; r < 80; ++r) EXPECT_EQ(packed[k * 80 + r], r < 70 ? w(r, k) : 0.f);
  }
  {  // 400 rows = 25 vectors, 2 columns (at most 14): blocks of 13 and 12 vectors, each contiguous
    const Mat<float> w = Mat<float>::Random(400, depth);
    std::vector<float> packed(dense::packedSize(400, depth), -1.f);
    dense::packForward(w.data(), 400, 400, depth, 2, packed.data());
    for (int k = 0; k < depth; ++k) {
      for (int r = 0; r < 208; ++r) EXPECT_EQ(packed[k * 208 + r], w(r, k));
      for (int r = 0; r < 192; ++r) EXPECT_EQ(packed[208 * depth + k * 192 + r], w(208 + r, k));
    }
  }
  float unused[16];
  EXPECT_THROW(dense::packForward(unused, 1, 1, 1, 5, unused), std::exception);
  EXPECT_THROW(dense::packForward(unused, 1, 1, 1, 0, unused), std::exception);
}

// AVX2's narrow tiles: at most 12, 6, 4 and 3 vectors of 8 rows for 1-4 columns.
TEST(DenseKernelsPack, Avx2ForwardPackHoldsEachRowBlockContiguouslyZeroPadded) {
  if (!dense::kAvailable || dense::kLanes != 8) GTEST_SKIP() << "AVX2's layout (this build: AVX-512 or none)";
  const int depth = 3;
  {  // 20 rows = 3 vectors: one block for 4 columns (at most 3 vectors), 4 rows of zeros
    const Mat<float> w = Mat<float>::Random(20, depth);
    std::vector<float> packed(dense::packedSize(20, depth), -1.f);
    dense::packForward(w.data(), 20, 20, depth, 4, packed.data());
    for (int k = 0; k < depth; ++k)
      for (int r = 0; r < 24; ++r) EXPECT_EQ(packed[k * 24 + r], r < 20 ? w(r, k) : 0.f);
  }
  {  // 100 rows = 13 vectors, 2 columns (at most 6): blocks of 5, 4 and 4 vectors, each contiguous
    const Mat<float> w = Mat<float>::Random(100, depth);
    std::vector<float> packed(dense::packedSize(100, depth), -1.f);
    dense::packForward(w.data(), 100, 100, depth, 2, packed.data());
    for (int k = 0; k < depth; ++k) {
      for (int r = 0; r < 40; ++r) EXPECT_EQ(packed[k * 40 + r], w(r, k));
      for (int r = 0; r < 32; ++r) EXPECT_EQ(packed[40 * depth + k * 32 + r], w(40 + r, k));
      for (int r = 0; r < 32; ++r) EXPECT_EQ(packed[72 * depth + k * 32 + r], r < 28 ? w(72 + r, k) : 0.f);
    }
  }
  float unused[16];
  EXPECT_THROW(dense::packForward(unused, 1, 1, 1, 5, unused), std::exception);
}

TEST(DenseKernelsPack, PanelsHoldRowsOfOpWZeroPadded) {
  if (!dense::kAvailable) GTEST_SKIP() << "built without AVX-512 or AVX2";
  // 4 vectors and 6 rows = 5 vectors = one 3-vector panel and one 2-vector panel with L + 6 valid
  // rows (L lanes: AVX-512 70 rows as 48 + 32 with 22 valid, AVX2 38 rows as 24 + 16 with 14).
  const int L = dense::kLanes;
  const int rows = 4 * L + 6, depth = 3;
  const Mat<float> w = Mat<float>::Random(rows, depth);
  std::vector<float> packed(dense::packedSize(rows, depth), -1.f);
  ASSERT_EQ(packed.size(), size_t(5 * L * 3));
  dense::pack(w.data(), rows, false, rows, depth, packed.data());
  for (int k = 0; k < depth; ++k) {
    for (int r = 0; r < 3 * L; ++r) EXPECT_EQ(packed[k * 3 * L + r], w(r, k));
    for (int r = 0; r < 2 * L; ++r)
      EXPECT_EQ(packed[3 * L * depth + k * 2 * L + r], r < L + 6 ? w(3 * L + r, k) : 0.f);
  }
}

// Threads that pack a part each (the fused backward's W^T) write together exactly the bytes of
// one pack: every panel once, padding included, at 1 to 4 parts and shapes of 1 to 9 panels.
TEST(DenseKernelsPack, PartsWriteTogetherWhatOnePackWrites) {
  if (!dense::kAvailable) GTEST_SKIP() << "built without AVX-512 or AVX2";
  for (const auto& [rows, depth] : {std::pair{7, 5}, std::pair{70, 3}, std::pair{400, 74}, std::pair{100, 200}}) {
    const Mat<float> w = Mat<float>::Random(depth, rows);  // transposed: W^T is rows x depth
    std::vector<float> whole(dense::packedSize(rows, depth), -1.f);
    dense::pack(w.data(), depth, true, rows, depth, whole.data());
    for (int parts = 1; parts <= 4; ++parts) {
      std::vector<float> together(whole.size(), -1.f);
      for (int part = parts - 1; part >= 0; --part)
        dense::pack(w.data(), depth, true, rows, depth, together.data(), part, parts);
      EXPECT_EQ(together, whole) << rows << " x " << depth << " in " << parts << " parts";
    }
  }
  float unused[16];
  EXPECT_THROW(dense::pack(unused, 1, true, 1, 1, unused, 2, 2), std::exception);
  EXPECT_THROW(dense::pack(unused, 1, true, 1, 1, unused, 0, 0), std::exception);
}

// The fused float engine against the double generic one, same parameters: outputs, parameter
// gradients and input gradients, at batches that use one thread, several, and partial chunks.
void expectFusedMatchesGeneric(const MlpShape& shape, int batch, int threads) {
  ParameterSet<float> pf;
  ParameterSet<double> pd;
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  Mlp<float> f(pf, "net", shape);
  Mlp<double> d(pd, "net", shape);
  pf.finalize();
  pd.finalize();
  Rng rng(3);
  f.initialize(rng);
  pd.values() = pf.values().cast<double>();
  const Mat<float> x = Mat<float>::Random(shape.input, batch);
  const Mat<float> dy = Mat<float>::Random(shape.output, batch);
  const Mat<double> yd = d.forward(x.cast<double>());
  const Mat<float> yf = f.forward(x);
  EXPECT_LT((yf.cast<double>() - yd).cwiseAbs().maxCoeff(), 1e-4) << "forward, batch " << batch;
  EXPECT_EQ(f.infer(x), yf) << "infer and forward differ";
  f.forward(x);

  Mat<float> dxf(shape.input, batch);
  Mat<double> dxd(shape.input, batch);
  MatRef<float> dxf_ref(dxf);
  MatRef<double> dxd_ref(dxd);
  pf.grads().setConstant(0.5f);  // backward accumulates
  pd.grads().setConstant(0.5);
  f.backward(dy, &dxf_ref);
  d.backward(dy.cast<double>(), &dxd_ref);
  const double scale = 1.0 + pd.grads().cwiseAbs().maxCoeff();
  EXPECT_LT((pf.grads().cast<double>() - pd.grads()).cwiseAbs().maxCoeff(), 1e-5 * scale) << "grads, batch " << batch;
  EXPECT_LT((dxf.cast<double>() - dxd).cwiseAbs().maxCoeff(), 1e-4) << "dx, batch " << batch;
  omp_set_num_threads(saved);
}

TEST(MlpFusedEngine, MatchesTheGenericEngineInDoubleForTheHumanoidPolicy) {
  if (!dense::kAvailable) GTEST_SKIP() << "built without AVX-512 or AVX2";
  const MlpShape shape{74, {400, 200, 100}, 21, Activation::kElu, Activation::kIdentity};
  for (int batch : {1, 13, 300, 1000}) expectFusedMatchesGeneric(shape, batch, 2);
  expectFusedMatchesGeneric(shape, 777, 1);
}

// Frozen parameters: 1-4 columns read packed weights (built on first use), with the bits of the
// unfrozen path; 5 columns and more the batch path; and nothing can write the weights any more,
// so the packs cannot go stale.
TEST(MlpFusedEngine, FrozenParametersInferWithTheSameBitsAndRefuseWrites) {
  if (!dense::kAvailable) GTEST_SKIP() << "built without AVX-512 or AVX2";
  ParameterSet<float> params;
  Mlp<float> net(params, "net", MlpShape{74, {400, 200, 100}, 21, Activation::kElu, Activation::kIdentity});
  Rng rng(3);
  net.initialize(rng, 1.f);
  const Mat<float> x = Mat<float>::Random(74, 6);
  std::vector<Mat<float>> before;
  for (int n = 1; n <= 6; ++n) before.emplace_back(net.infer(x.leftCols(n)));
  params.freeze();
  for (int round = 0; round < 2; ++round)  // packs built, then reused
    for (int n = 1; n <= 6; ++n)
      EXPECT_TRUE(Mat<float>(net.infer(x.leftCols(n))) == before[n - 1]) << n << " columns, round " << round;
  EXPECT_TRUE(params.frozen());
  EXPECT_THROW(params.values(), std::exception);
  EXPECT_THROW(params.value(0, 1, 1), std::exception);
  EXPECT_EQ(std::as_const(params).values().size(), params.size());  // reading stays allowed
}

TEST(MlpFusedEngine, MatchesTheGenericEngineForOtherActivationsAndWidths) {
  if (!dense::kAvailable) GTEST_SKIP() << "built without AVX-512 or AVX2";
  expectFusedMatchesGeneric(MlpShape{9, {33, 17}, 3, Activation::kTanh, Activation::kTanh}, 600, 2);
  expectFusedMatchesGeneric(MlpShape{5, {64}, 1, Activation::kRelu, Activation::kElu}, 530, 2);
  expectFusedMatchesGeneric(MlpShape{7, {}, 2, Activation::kElu, Activation::kIdentity}, 40, 2);
}

}  // namespace
}  // namespace masa::nn
