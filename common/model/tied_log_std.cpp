#include "common/model/tied_log_std.hpp"

#include <algorithm>
#include <utility>

#include "common/core/check.hpp"

namespace masa::model {

template <typename S>
TiedLogStd<S>::TiedLogStd(nn::ParameterSet<S>& params, const std::string& name, std::vector<int> classes)
    : params_(&params), classes_(std::move(classes)) {
  MASA_CHECK(!classes_.empty(), "log-std needs at least one action dimension");
  num_classes_ = *std::max_element(classes_.begin(), classes_.end()) + 1;
  for (int c : classes_) MASA_CHECK(c >= 0, "negative class id " << c);
  offset_ = params.reserve(name, num_classes_, 1);
}

template <typename S>
void TiedLogStd<S>::initialize(S value) {
  params_->value(offset_, num_classes_, 1).setConstant(value);
}

template <typename S>
void TiedLogStd<S>::get(VecRef<S> log_std) const {
  MASA_CHECK(log_std.size() == actDim(), "log_std has " << log_std.size() << " entries, expected " << actDim());
  const S* p = std::as_const(*params_).values().data() + offset_;
  for (int d = 0; d < actDim(); ++d) log_std(d) = p[classes_[d]];
}

template <typename S>
void TiedLogStd<S>::backward(const ConstVecRef<S>& dlog_std) {
  MASA_CHECK(dlog_std.size() == actDim(), "dlog_std has " << dlog_std.size() << " entries, expected " << actDim());
  S* g = params_->grads().data() + offset_;
  for (int d = 0; d < actDim(); ++d) g[classes_[d]] += dlog_std(d);
}

template class TiedLogStd<float>;
template class TiedLogStd<double>;

}  // namespace masa::model
