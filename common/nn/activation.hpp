// Elementwise activations with vectorized forward and derivative.
// ELU is written as max(z,0) + exp(min(z,0)) - 1: Eigen's select() is not vectorized.
#pragma once

#include <string>

#include "common/core/types.hpp"

namespace masa::nn {

enum class Activation { kIdentity, kElu, kTanh, kRelu };

Activation parseActivation(const std::string& name);  // "identity" | "elu" | "tanh" | "relu"; throws otherwise
std::string activationName(Activation a);

// y = f(z), in place allowed (y may alias z).
template <typename S>
void activate(Activation a, const ConstMatRef<S>& z, MatRef<S> y);
// dz = dy * f'(z) given z and y = f(z) (whichever is cheaper is used); dz may alias dy.
template <typename S>
void activateBackward(Activation a, const ConstMatRef<S>& z, const ConstMatRef<S>& y, const ConstMatRef<S>& dy,
                      MatRef<S> dz);

}  // namespace masa::nn
