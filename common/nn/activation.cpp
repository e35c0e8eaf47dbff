// Elementwise activations. Every form is branch-free so that Eigen (or GCC) vectorizes it; the
// derivatives are written in terms of y where that saves an exp or a compare.
#include "common/nn/activation.hpp"

#include "common/core/check.hpp"

namespace masa::nn {

Activation parseActivation(const std::string& name) {
  if (name == "identity") return Activation::kIdentity;
  if (name == "elu") return Activation::kElu;
  if (name == "tanh") return Activation::kTanh;
  if (name == "relu") return Activation::kRelu;
  MASA_CHECK(false, "unknown activation '" << name << "' (expected identity, elu, tanh or relu)");
  return Activation::kIdentity;
}

std::string activationName(Activation a) {
  switch (a) {
    case Activation::kIdentity: return "identity";
    case Activation::kElu: return "elu";
    case Activation::kTanh: return "tanh";
    case Activation::kRelu: return "relu";
  }
  MASA_CHECK(false, "invalid activation value " << static_cast<int>(a));
  return {};
}

template <typename S>
void activate(Activation a, const ConstMatRef<S>& z, MatRef<S> y) {
  MASA_CHECK(z.rows() == y.rows() && z.cols() == y.cols(),
             "activate: z is " << z.rows() << "x" << z.cols() << ", y is " << y.rows() << "x" << y.cols());
  switch (a) {
    case Activation::kIdentity:
      if (y.data() != z.data()) y = z;
      return;
    case Activation::kElu:
      // The inner parentheses keep y == z exactly for z > 0 (z + (1 - 1), not (z + 1) - 1).
      y.array() = z.array().max(S(0)) + (z.array().min(S(0)).exp() - S(1));
      return;
    case Activation::kTanh:
      y.array() = z.array().tanh();
      return;
    case Activation::kRelu:
      y.array() = z.array().max(S(0));
      return;
  }
}

template <typename S>
void activateBackward(Activation a, const ConstMatRef<S>& z, const ConstMatRef<S>& y, const ConstMatRef<S>& dy,
                      MatRef<S> dz) {
  MASA_CHECK(z.rows() == dy.rows() && z.cols() == dy.cols() && y.rows() == dy.rows() && y.cols() == dy.cols() &&
                 dz.rows() == dy.rows() && dz.cols() == dy.cols(),
             "activateBackward: z " << z.rows() << "x" << z.cols() << ", y " << y.rows() << "x" << y.cols() << ", dy "
                                    << dy.rows() << "x" << dy.cols() << ", dz " << dz.rows() << "x" << dz.cols());
  switch (a) {
    case Activation::kIdentity:
      if (dz.data() != dy.data()) dz = dy;
      return;
    case Activation::kElu:
      // f'(z) is 1 for z > 0 and exp(z) = y + 1 otherwise; min(y, 0) + 1 gives both without a compare.
      dz.array() = dy.array() * (y.array().min(S(0)) + S(1));
      return;
    case Activation::kTanh:
      dz.array() = dy.array() * (S(1) - y.array().square());
      return;
    case Activation::kRelu:
      // Plain loops: GCC turns the conditional into a masked blend, Eigen's select() stays scalar.
      for (Eigen::Index c = 0; c < dz.cols(); ++c) {
        const S* zc = z.col(c).data();
        const S* dyc = dy.col(c).data();
        S* dzc = dz.col(c).data();
        for (Eigen::Index r = 0; r < dz.rows(); ++r) dzc[r] = zc[r] > S(0) ? dyc[r] : S(0);
      }
      return;
  }
}

template void activate<float>(Activation, const ConstMatRef<float>&, MatRef<float>);
template void activate<double>(Activation, const ConstMatRef<double>&, MatRef<double>);
template void activateBackward<float>(Activation, const ConstMatRef<float>&, const ConstMatRef<float>&,
                                      const ConstMatRef<float>&, MatRef<float>);
template void activateBackward<double>(Activation, const ConstMatRef<double>&, const ConstMatRef<double>&,
                                       const ConstMatRef<double>&, MatRef<double>);

}  // namespace masa::nn
