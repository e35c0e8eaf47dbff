// Learned log standard deviations tied by class: action dimensions with the same class id share
// one parameter. MASA ties by the symmetry's orbit classes (one std per limb slot shared by all
// limbs; central stds invariant under the central signed permutation), which makes the action
// distribution equivariant and not only its mean.
#pragma once

#include <string>
#include <vector>

#include "common/nn/parameter_set.hpp"

namespace masa::model {

template <typename S>
class TiedLogStd {
 public:
  TiedLogStd(nn::ParameterSet<S>& params, const std::string& name, std::vector<int> classes);

  void initialize(S value);
  int actDim() const { return static_cast<int>(classes_.size()); }
  int numClasses() const { return num_classes_; }
  const std::vector<int>& classes() const { return classes_; }

  void get(VecRef<S> log_std) const;               // act_dim values
  void backward(const ConstVecRef<S>& dlog_std);  // accumulates into the class parameters

 private:
  nn::ParameterSet<S>* params_;
  std::vector<int> classes_;
  int num_classes_ = 0;
  int offset_ = 0;
};

}  // namespace masa::model
