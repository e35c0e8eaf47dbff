// Adam (Kingma & Ba) with bias correction, in PyTorch's arrangement of the update:
//   p -= (lr / (1 - b1^t)) * m / (sqrt(v) / sqrt(1 - b2^t) + eps).
#include "common/nn/adam.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/core/binary_io.hpp"
#include "common/core/check.hpp"

namespace masa::nn {

namespace {
constexpr char kAdamMagic[8] = {'M', 'A', 'S', 'A', 'A', 'D', 'M', '1'};

using io::writeArray;
using io::writePod;
template <typename T>
void readPod(std::istream& is, T& v, const char* what) {
  if (!io::readPod(is, v)) throw std::runtime_error(std::string("Adam state: stream ends while reading ") + what);
}
}  // namespace

template <typename S>
Adam<S>::Adam(ParameterSet<S>& params, AdamConfig<S> config) : Adam(params, config, 0, params.size()) {}

template <typename S>
Adam<S>::Adam(ParameterSet<S>& params, AdamConfig<S> config, int begin, int end)
    : params_(&params), config_(config), begin_(begin), end_(end) {
  MASA_CHECK(params.finalized(), "Adam needs a finalized parameter set");
  MASA_CHECK(0 <= begin && begin <= end && end <= params.size(),
             "Adam range [" << begin << ", " << end << ") outside the parameter set's " << params.size() << " values");
  m_ = Vec<S>::Zero(end - begin);
  v_ = Vec<S>::Zero(end - begin);
}

template <typename S>
void Adam<S>::step() {
  MASA_CHECK(params_->size() >= end_ && end_ - begin_ == m_.size(),
             "Adam: parameter set has " << params_->size() << " values, state covers [" << begin_ << ", " << end_ << ")");
  MASA_CHECK(config_.lr >= S(0) && config_.eps > S(0), "Adam: lr " << config_.lr << ", eps " << config_.eps);
  ++t_;
  const S b1 = config_.beta1, b2 = config_.beta2;
  // Bias corrections in double: b2^t for b2 = 0.999 stays accurate far beyond float's reach.
  const double bc1 = 1.0 - std::pow(static_cast<double>(b1), static_cast<double>(t_));
  const double bc2 = 1.0 - std::pow(static_cast<double>(b2), static_cast<double>(t_));
  const S step_size = static_cast<S>(config_.lr / bc1);
  const S inv_sqrt_bc2 = static_cast<S>(1.0 / std::sqrt(bc2));
  // One pass in L1-sized blocks instead of three passes over the whole vectors; the arithmetic
  // (and so every bit of the result) is that of the three whole-vector expressions. The update is
  // elementwise, so the blocks can go to any thread: on two threads a serial Adam was 4% of a
  // 1024-column policy step.
  constexpr Eigen::Index kBlock = 2048;
  constexpr Eigen::Index kMinBlocksPerThread = 8;
  const Eigen::Index n = m_.size();
  const Eigen::Index blocks = (n + kBlock - 1) / kBlock;
  const int threads = omp_in_parallel() ? 1
                                        : static_cast<int>(std::clamp<Eigen::Index>(
                                              blocks / kMinBlocksPerThread, 1, std::max(1, omp_get_max_threads())));
  const S eps = config_.eps;
  const Vec<S>& grads = std::as_const(*params_).grads();
  Vec<S>& values = params_->values();  // (throws on frozen parameters, before any thread starts)
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1)
  for (Eigen::Index block = 0; block < blocks; ++block) {
    const Eigen::Index i = block * kBlock, len = std::min(kBlock, n - i);
    auto g = grads.segment(begin_ + i, len).array();
    auto m = m_.segment(i, len).array();
    auto v = v_.segment(i, len).array();
    m = b1 * m + (S(1) - b1) * g;
    v = b2 * v + (S(1) - b2) * g.square();
    values.segment(begin_ + i, len).array() -= step_size * m / (v.sqrt() * inv_sqrt_bc2 + eps);
  }
}

template <typename S>
void Adam<S>::save(std::ostream& os) const {
  os.write(kAdamMagic, sizeof(kAdamMagic));
  writePod(os, static_cast<std::uint32_t>(sizeof(S)));
  writePod(os, static_cast<std::int64_t>(m_.size()));
  writePod(os, static_cast<std::int64_t>(t_));
  writeArray(os, m_.data(), static_cast<std::size_t>(m_.size()));
  writeArray(os, v_.data(), static_cast<std::size_t>(v_.size()));
  if (!os) throw std::runtime_error("Adam state: write failed");
}

template <typename S>
void Adam<S>::load(std::istream& is) {
  char magic[sizeof(kAdamMagic)];
  if (!is.read(magic, sizeof(magic))) throw std::runtime_error("Adam state: stream ends while reading the magic");
  if (std::memcmp(magic, kAdamMagic, sizeof(magic)) != 0) throw std::runtime_error("Adam state: bad magic (not an Adam state)");
  std::uint32_t scalar = 0;
  std::int64_t n = 0, t = 0;
  readPod(is, scalar, "the scalar size");
  if (scalar != sizeof(S))
    throw std::runtime_error("Adam state: scalar size " + std::to_string(scalar) + " in the stream, " +
                             std::to_string(sizeof(S)) + " in the optimizer");
  readPod(is, n, "the state size");
  if (n != m_.size())
    throw std::runtime_error("Adam state: " + std::to_string(n) + " moments in the stream, " +
                             std::to_string(m_.size()) + " parameters in the optimizer");
  readPod(is, t, "the step count");
  if (t < 0) throw std::runtime_error("Adam state: negative step count " + std::to_string(t));
  // Read into temporaries so that a truncated stream leaves the optimizer as it was.
  Vec<S> m(n), v(n);
  if (!io::readArray(is, m.data(), static_cast<std::size_t>(n)) || !io::readArray(is, v.data(), static_cast<std::size_t>(n)))
    throw std::runtime_error("Adam state: stream ends inside the moments");
  m_.swap(m);
  v_.swap(v);
  t_ = t;
}

template <typename S>
S clipGradNorm(ParameterSet<S>& params, S max_norm) {
  MASA_CHECK(max_norm > S(0), "clipGradNorm: max_norm must be positive, got " << max_norm);
  const S norm = params.grads().norm();
  if (norm > max_norm) params.grads() *= max_norm / norm;
  return norm;
}

template class Adam<float>;
template class Adam<double>;
template float clipGradNorm<float>(ParameterSet<float>&, float);
template double clipGradNorm<double>(ParameterSet<double>&, double);

}  // namespace masa::nn
