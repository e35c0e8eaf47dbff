// The fused MLP engine's chunk width: the tuner times each candidate and keeps the fastest, and no
// width, forced or chosen while training, changes a bit of any result (issue #14).
#include <gtest/gtest.h>
#include <omp.h>

#include <random>

#include "common/nn/chunk_tuner.hpp"
#include "common/nn/mlp.hpp"

namespace masa::nn {
namespace {

// Feeds one candidate's steps: the first (uncounted) at `first_seconds`, the rest at `seconds`.
void feed(ChunkTuner& tuner, int columns, int per_thread, double first_seconds, double seconds) {
  tuner.record(columns, per_thread, first_seconds);
  for (int s = 1; s < ChunkTuner::kStepsPerCandidate; ++s) tuner.record(columns, per_thread, seconds);
}

TEST(ChunkTuner, TimesEveryCandidateInTurnThenKeepsTheFastest) {
  ChunkTuner tuner;
  const int columns = 4096, per_thread = 2048;
  EXPECT_EQ(tuner.width(per_thread), 128);
  // 128's first step is the fastest of all, but a first step after a switch does not count.
  feed(tuner, columns, per_thread, 0.001, 0.010);
  EXPECT_EQ(tuner.width(per_thread), 256);
  feed(tuner, columns, per_thread, 0.020, 0.008);
  EXPECT_EQ(tuner.width(per_thread), 512);
  EXPECT_FALSE(tuner.settled());
  feed(tuner, columns, per_thread, 0.020, 0.009);
  ASSERT_TRUE(tuner.settled());
  EXPECT_EQ(tuner.width(per_thread), 256);
  EXPECT_EQ(tuner.width(300), 256) << "a narrower share still rounds up to whole blocks";
  EXPECT_EQ(tuner.width(100), 128) << "never wider than one thread's share, in blocks";
  EXPECT_NE(tuner.summary().find("256 columns (measured"), std::string::npos) << tuner.summary();
  feed(tuner, columns, per_thread, 1e-9, 1e-9);
  EXPECT_EQ(tuner.width(per_thread), 256) << "settled means settled";
}

TEST(ChunkTuner, ABatchTooNarrowForTheNextCandidateSettlesOnWhatWasMeasured) {
  ChunkTuner tuner;
  feed(tuner, 200, 100, 0.01, 0.01);  // 128 measured; 100 columns a thread cannot fill 256
  EXPECT_FALSE(tuner.settled());
  tuner.record(200, 100, 0.01);
  ASSERT_TRUE(tuner.settled());
  EXPECT_EQ(tuner.width(4096), 128);
}

TEST(ChunkTuner, AForcedWidthMustBeWholeBlocks) {
  ChunkTuner tuner;
  EXPECT_THROW(tuner.force(100), std::exception);
  EXPECT_THROW(tuner.force(0), std::exception);
  tuner.force(384);
  EXPECT_TRUE(tuner.settled());
  EXPECT_EQ(tuner.width(4096), 384);
  EXPECT_EQ(tuner.summary(), "384 columns (forced)");
}

// Training steps of one network at a forced width (or tuned when width == 0): outputs, parameter
// gradients and input gradients of every step.
struct Steps {
  std::vector<Mat<float>> y, grads, dx;
  std::string summary;
};

Mat<float> uniform(int rows, int cols, Rng& rng) {
  std::uniform_real_distribution<float> dist(-1.f, 1.f);
  Mat<float> m(rows, cols);
  for (float& v : m.reshaped()) v = dist(rng);
  return m;
}

Steps trainAtWidth(int width, int batch, int steps) {
  const MlpShape shape{23, {150, 60}, 7, Activation::kElu, Activation::kIdentity};
  ParameterSet<float> params;
  Mlp<float> mlp(params, "net", shape);
  params.finalize();
  Rng rng(5);
  mlp.initialize(rng);
  if (width > 0) mlp.forceChunkWidth(width);
  Rng data(9);
  Steps out;
  for (int s = 0; s < steps; ++s) {
    const Mat<float> x = uniform(shape.input, batch, data);
    const Mat<float> dy = uniform(shape.output, batch, data);
    params.zeroGrad();
    out.y.push_back(mlp.forward(x));
    Mat<float> dx(shape.input, batch);
    MatRef<float> dx_ref(dx);
    mlp.backward(dy, &dx_ref);
    out.grads.push_back(params.grads());
    out.dx.push_back(dx);
  }
  out.summary = mlp.chunkTuner().summary();
  return out;
}

TEST(MlpChunkWidth, EveryWidthAndTheTuningItselfGiveBitIdenticalResults) {
  if (!dense::kAvailable) GTEST_SKIP() << "the fused engine needs AVX-512 or AVX2";
  const int saved = omp_get_max_threads();
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    for (int batch : {777, 2100}) {  // blocks split unevenly over the threads; a partial last block
      const int steps = 3 * ChunkTuner::kStepsPerCandidate + 2;
      const Steps reference = trainAtWidth(128, batch, steps);
      for (int width : {0, 256, 384, 512}) {
        const Steps other = trainAtWidth(width, batch, steps);
        for (int s = 0; s < steps; ++s) {
          const std::string where = "width " + std::to_string(width) + " (0: tuned), batch " + std::to_string(batch) +
                                    ", threads " + std::to_string(threads) + ", step " + std::to_string(s);
          EXPECT_TRUE(other.y[s] == reference.y[s]) << where;
          EXPECT_TRUE(other.grads[s] == reference.grads[s]) << where;
          EXPECT_TRUE(other.dx[s] == reference.dx[s]) << where;
        }
        if (width == 0) {
          EXPECT_NE(other.summary.find("measured"), std::string::npos) << other.summary;
        }
      }
    }
  }
  omp_set_num_threads(saved);
}

}  // namespace
}  // namespace masa::nn
