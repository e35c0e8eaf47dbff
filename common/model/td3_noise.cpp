#include "common/model/td3_noise.hpp"

#include "common/core/check.hpp"

namespace masa::sac::td3 {

template <typename S>
void noisyActions(const ConstMatRef<S>& mean, const ConstMatRef<S>& eps, S sigma, S noise_clip, MatRef<S> actions) {
  MASA_CHECK(mean.rows() == eps.rows() && mean.cols() == eps.cols() && actions.rows() == mean.rows() &&
                 actions.cols() == mean.cols(),
             "TD3 noise: mean, noise and actions must be the same act_dim x B");
  MASA_CHECK(sigma >= S(0) && noise_clip >= S(0), "TD3 noise: negative sigma or clip");
  actions = (mean.array().tanh() + (sigma * eps.array()).cwiseMax(-noise_clip).cwiseMin(noise_clip))
                .cwiseMax(S(-1))
                .cwiseMin(S(1))
                .matrix();
}

template void noisyActions<float>(const ConstMatRef<float>&, const ConstMatRef<float>&, float, float, MatRef<float>);
template void noisyActions<double>(const ConstMatRef<double>&, const ConstMatRef<double>&, double, double,
                                   MatRef<double>);

}  // namespace masa::sac::td3
