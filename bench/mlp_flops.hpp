// FLOPs of an MLP's products per sample, counted exactly: 2 * in * out per layer forward; a
// training step adds 4 * in * out backward (dW and dx) less the first layer's dx, which training
// does not compute. Elementwise work is not counted. Shared by the benchmarks that quote GFLOP/s,
// with the network they time.
#pragma once

#include "common/nn/mlp.hpp"

namespace masa::bench {

// The humanoid-sized network the learner-step benchmarks time: 74 -> 400 -> 200 -> 100 -> output,
// ELU, float (the policy has 21 outputs, the critic 1).
inline constexpr int kHumanoidObs = 74, kHumanoidAct = 21;
inline nn::MlpShape humanoidNetwork(int output) {
  return nn::MlpShape{kHumanoidObs, {400, 200, 100}, output, nn::Activation::kElu, nn::Activation::kIdentity};
}

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
