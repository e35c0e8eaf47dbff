#include "common/nn/optimized_net.hpp"

#include "common/core/check.hpp"

namespace masa::nn {
namespace {
template <typename S>
AdamConfig<S> adamAt(double lr) {
  AdamConfig<S> c;
  c.lr = static_cast<S>(lr);
  return c;
}
}  // namespace

template <typename S>
void polyakUpdate(const ParameterSet<S>& online, ParameterSet<S>& target, S rate) {
  MASA_CHECK(online.size() == target.size(),
             "a target network of " << target.size() << " parameters cannot follow one of " << online.size());
  target.values() += rate * (online.values() - target.values());
}

template <typename S>
OptimizedNet<S>::OptimizedNet(ParameterSet<S>& params, double lr, ParameterSet<S>* target)
    : params_(&params), target_(target), adam_(params, adamAt<S>(lr)) {
  MASA_CHECK(!target || target->size() == params.size(),
             "a target network of " << target->size() << " parameters for one of " << params.size());
}

template <typename S>
OptimizedNet<S>::OptimizedNet(ParameterSet<S>& params, double lr, int begin, int end)
    : params_(&params), adam_(params, adamAt<S>(lr), begin, end) {}

template <typename S>
ParameterSet<S>& OptimizedNet<S>::target() {
  MASA_CHECK(target_, "this network has no target");
  return *target_;
}

template <typename S>
void OptimizedNet<S>::copyToTarget() {
  target().values() = params_->values();
}

template <typename S>
void OptimizedNet<S>::updateTarget(S rate) {
  polyakUpdate(*params_, target(), rate);
}

template void polyakUpdate<float>(const ParameterSet<float>&, ParameterSet<float>&, float);
template void polyakUpdate<double>(const ParameterSet<double>&, ParameterSet<double>&, double);
template class OptimizedNet<float>;
template class OptimizedNet<double>;

}  // namespace masa::nn
