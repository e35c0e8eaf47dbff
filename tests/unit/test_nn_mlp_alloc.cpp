// Checks that the MLP's training step allocates nothing, with the process-wide allocation counter
// of alloc_counter.hpp.
#include <gtest/gtest.h>

#include <memory>

#include "alloc_counter.hpp"
#include "common/nn/adam.hpp"
#include "common/nn/mlp.hpp"

namespace masa::nn {
namespace {

// Keeps the compiler from eliding an allocation whose result is otherwise unused.
void escape(void* p) { asm volatile("" : : "g"(p) : "memory"); }

long allocations() { return test::allocationCount(); }

template <typename S>
void expectNoAllocationInTrainingStep(const MlpShape& shape, int first_batch, int later_batch) {
  ParameterSet<S> params;
  Mlp<S> mlp(params, "net", shape);
  params.finalize();
  Rng rng(9);
  mlp.initialize(rng);
  Adam<S> adam(params);
  const Mat<S> x1 = Mat<S>::Random(shape.input, first_batch), x2 = Mat<S>::Random(shape.input, later_batch);
  const Mat<S> d1 = Mat<S>::Random(shape.output, first_batch), d2 = Mat<S>::Random(shape.output, later_batch);
  Mat<S> dx1(shape.input, first_batch), dx2(shape.input, later_batch);
  MatRef<S> dx1_ref(dx1), dx2_ref(dx2);

  mlp.forward(x1);
  mlp.backward(d1, &dx1_ref);
  adam.step();

  const long before = allocations();
  for (int rep = 0; rep < 2; ++rep) {
    params.zeroGrad();
    mlp.forward(x1);
    mlp.backward(d1, &dx1_ref);
    mlp.forward(x2);
    mlp.backward(d2, &dx2_ref);
    clipGradNorm(params, S(0.5));
    adam.step();
    mlp.infer(x2);
  }
  EXPECT_EQ(allocations() - before, 0);
}

TEST(MlpAllocation, CounterSeesEigenAndNewAllocations) {
  if (!test::allocationCountingEnabled()) GTEST_SKIP() << "malloc is owned by a sanitizer";
  const long before = allocations();
  {
    Mat<float> m(17, 3);
    escape(m.data());
  }
  {
    auto p = std::make_unique<int>(3);
    escape(p.get());
  }
  EXPECT_GE(allocations() - before, 2);
}

TEST(MlpAllocation, NoneInForwardBackwardAdamAtTheSameOrSmallerBatch) {
  if (!test::allocationCountingEnabled()) GTEST_SKIP() << "malloc is owned by a sanitizer";
  MlpShape shape;
  shape.input = 11;
  shape.hidden = {40, 24};
  shape.output = 5;
  expectNoAllocationInTrainingStep<float>(shape, 16, 7);
  expectNoAllocationInTrainingStep<double>(shape, 16, 1);
}

// The robot runner's path: frozen parameters, 1-4 columns from packs made on each count's first
// call; after those, inference allocates nothing.
TEST(MlpAllocation, NoneInFrozenInferenceAfterTheFirstCallOfEachColumnCount) {
  if (!test::allocationCountingEnabled()) GTEST_SKIP() << "malloc is owned by a sanitizer";
  ParameterSet<float> params;
  Mlp<float> mlp(params, "net", MlpShape{74, {400, 200, 100}, 21, Activation::kElu, Activation::kIdentity});
  params.finalize();
  Rng rng(9);
  mlp.initialize(rng);
  params.freeze();
  const Mat<float> x = Mat<float>::Random(74, 4);
  for (int n = 1; n <= 4; ++n) mlp.infer(x.leftCols(n));
  const long before = allocations();
  for (int rep = 0; rep < 3; ++rep)
    for (int n = 1; n <= 4; ++n) escape(mlp.infer(x.leftCols(n)).data());
  EXPECT_EQ(allocations() - before, 0);
}

TEST(MlpAllocation, NoneForTheHumanoidPolicyFromActorToMinibatchSizes) {
  if (!test::allocationCountingEnabled()) GTEST_SKIP() << "malloc is owned by a sanitizer";
  MlpShape shape;
  shape.input = 74;
  shape.hidden = {400, 200, 100};
  shape.output = 21;
  expectNoAllocationInTrainingStep<float>(shape, 16, 1);
  expectNoAllocationInTrainingStep<float>(shape, 512, 256);
  expectNoAllocationInTrainingStep<float>(shape, 4096, 1000);  // products split over threads
}

}  // namespace
}  // namespace masa::nn
