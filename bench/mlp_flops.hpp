// FLOPs of an MLP's products per sample, counted exactly: 2 * in * out per layer forward; a
// training step adds 4 * in * out backward (dW and dx) less the first layer's dx, which training
// does not compute. Elementwise work is not counted. Shared by the benchmarks that quote GFLOP/s.
#pragma once

#include "common/nn/mlp.hpp"

namespace masa::bench {

inline double forwardFlopsPerSample(const nn::MlpShape& s) {
  int in = s.input;
  double f = 0;
  for (int out : s.hidden) f += 2.0 * in * out, in = out;
  return f + 2.0 * in * s.output;
}

inline double trainingFlopsPerSample(const nn::MlpShape& s) {
  const int first = s.hidden.empty() ? s.output : s.hidden.front();
  return 3.0 * forwardFlopsPerSample(s) - 2.0 * s.input * first;
}

}  // namespace masa::bench
