#include "common/model/equivariance_check.hpp"

#include "common/model/diag_gaussian.hpp"

#include <limits>

namespace masa::model {
namespace {
// A NaN or infinite output is no symmetry: the error is then infinite (maxCoeff and std::max would
// drop a NaN, and a policy whose mean held a NaN passed with error 0).
template <typename A, typename B>
double maxRelativeError(const A& got, const B& want) {
  const Eigen::ArrayXXd err = (got - want).array().abs() / (want.array().abs() + 1.0);
  if (!err.allFinite()) return std::numeric_limits<double>::infinity();
  return err.maxCoeff();
}
}  // namespace

template <typename S>
EquivarianceReport checkEquivariance(ActorCritic<S>& model, const ConstMatRef<S>& obs, const ConstMatRef<S>& actions) {
  const auto& spec = model.spec();
  const Eigen::Index b = obs.cols();
  MASA_CHECK(actions.cols() == b && actions.rows() == model.actDim(), "actions must be act_dim x batch");
  Vec<S> log_std(model.actDim());
  model.logStd(log_std);

  model.forward(obs);
  const Mat<S> mean = model.mean();
  const Mat<S> value = model.value();
  Mat<S> logp(1, b);
  gaussian::logProb<S>(mean, log_std, actions, logp);

  EquivarianceReport report;
  Mat<S> obs_i(obs.rows(), b), act_i(actions.rows(), b), mean_want(mean.rows(), b), logp_i(1, b);
  for (int i = 1; i < spec.numAgents(); ++i) {
    spec.obsTransform(i).template apply<S>(obs, obs_i);
    spec.actTransform(i).template apply<S>(actions, act_i);
    spec.actTransform(i).template apply<S>(mean, mean_want);
    model.forward(obs_i);
    gaussian::logProb<S>(model.mean(), log_std, act_i, logp_i);
    report.mean_error = std::max(report.mean_error, maxRelativeError(model.mean().template cast<double>(),
                                                                    mean_want.template cast<double>()));
    report.value_error = std::max(report.value_error, maxRelativeError(model.value().template cast<double>(),
                                                                      value.template cast<double>()));
    report.logp_error =
        std::max(report.logp_error, maxRelativeError(logp_i.template cast<double>(), logp.template cast<double>()));
  }
  return report;
}

template EquivarianceReport checkEquivariance<float>(ActorCritic<float>&, const ConstMatRef<float>&,
                                                     const ConstMatRef<float>&);
template EquivarianceReport checkEquivariance<double>(ActorCritic<double>&, const ConstMatRef<double>&,
                                                      const ConstMatRef<double>&);

}  // namespace masa::model
