// One network as the off-policy learners train it (SAC, TD3, IQL): its parameters, or one
// contiguous range of them, stepped by an Adam of their own at the rate the learner's config gives,
// and, for a network whose bootstrapped targets must move slowly, a target copy of the parameters
// that follows them by Polyak averaging. The parameters and the target belong to the caller, who
// also saves them: a trainer's state file keeps its own order of networks and optimizers.
#pragma once

#include <iosfwd>

#include "common/nn/adam.hpp"
#include "common/nn/parameter_set.hpp"

namespace masa::nn {

// target <- target + rate (online - target), value by value. Rate 1 reaches the online values only
// up to rounding; OptimizedNet::copyToTarget is the exact copy. Throws when the sizes differ.
template <typename S>
void polyakUpdate(const ParameterSet<S>& online, ParameterSet<S>& target, S rate);

template <typename S>
class OptimizedNet {
 public:
  // Adam at learning rate lr (its other settings the defaults) on all of params. With a target
  // (of params' size, checked), copyToTarget and updateTarget move it.
  OptimizedNet(ParameterSet<S>& params, double lr, ParameterSet<S>* target = nullptr);
  // Adam on params' values [begin, end) only, no target: parts of one model trained at their own
  // rates (IQL's actor and value function in one ActorCritic).
  OptimizedNet(ParameterSet<S>& params, double lr, int begin, int end);

  // One Adam update from the parameters' gradients.
  void step() { adam_.step(); }
  // The rate of the steps from now on (a schedule's).
  void setLearningRate(double lr) { adam_.config().lr = static_cast<S>(lr); }
  const Adam<S>& adam() const { return adam_; }

  // target <- parameters, exactly (a fresh target) or by Polyak at `rate` (after a step).
  void copyToTarget();
  void updateTarget(S rate);

  // Adam's moments and step count, for a trainer's state file.
  void saveOptimizer(std::ostream& os) const { adam_.save(os); }
  void loadOptimizer(std::istream& is) { adam_.load(is); }

 private:
  ParameterSet<S>& target();

  ParameterSet<S>* params_;
  ParameterSet<S>* target_ = nullptr;
  Adam<S> adam_;
};

}  // namespace masa::nn
