// Counts every heap allocation of the process by interposing malloc and friends (forwarding to
// glibc's own entry points). operator new alone would miss Eigen, which allocates with malloc.
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <memory>

#include "common/nn/adam.hpp"
#include "common/nn/mlp.hpp"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || defined(__SANITIZE_MEMORY__)
#define MASA_COUNT_MALLOC 0  // sanitizers own malloc
#else
#define MASA_COUNT_MALLOC 1
#endif

#if MASA_COUNT_MALLOC
namespace {
std::atomic<long> g_allocations{0};
}

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);

void* malloc(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
void* aligned_alloc(std::size_t align, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(align, n);
}
int posix_memalign(void** out, std::size_t align, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  *out = __libc_memalign(align, n);
  return *out ? 0 : 12;  // ENOMEM
}
void free(void* p) { __libc_free(p); }
}
#endif

namespace masa::nn {
namespace {

// Keeps the compiler from eliding an allocation whose result is otherwise unused.
void escape(void* p) { asm volatile("" : : "g"(p) : "memory"); }

long allocations() {
#if MASA_COUNT_MALLOC
  return g_allocations.load();
#else
  return 0;
#endif
}

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
#if !MASA_COUNT_MALLOC
  GTEST_SKIP() << "malloc is owned by a sanitizer";
#endif
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
#if !MASA_COUNT_MALLOC
  GTEST_SKIP() << "malloc is owned by a sanitizer";
#endif
  MlpShape shape;
  shape.input = 11;
  shape.hidden = {40, 24};
  shape.output = 5;
  expectNoAllocationInTrainingStep<float>(shape, 16, 7);
  expectNoAllocationInTrainingStep<double>(shape, 16, 1);
}

TEST(MlpAllocation, NoneForTheHumanoidPolicyFromActorToMinibatchSizes) {
#if !MASA_COUNT_MALLOC
  GTEST_SKIP() << "malloc is owned by a sanitizer";
#endif
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
