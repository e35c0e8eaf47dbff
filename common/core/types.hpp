// Matrix conventions shared by every numeric module.
//
// A batch is stored column-major as features x batch: each sample is one contiguous column, so a
// dense layer is a single GEMM  Y = W X  and an observation buffer from a simulator can be viewed
// as a batch without copying.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>

namespace masa {

template <typename S>
using Mat = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;  // features x batch
template <typename S>
using Vec = Eigen::Matrix<S, Eigen::Dynamic, 1>;

template <typename S>
using MatRef = Eigen::Ref<Mat<S>>;
template <typename S>
using ConstMatRef = Eigen::Ref<const Mat<S>>;
template <typename S>
using VecRef = Eigen::Ref<Vec<S>>;
template <typename S>
using ConstVecRef = Eigen::Ref<const Vec<S>>;

// The one random generator type. Every random draw in masa takes a Rng& that the caller seeded,
// so the same seed reproduces the same run.
using Rng = std::mt19937_64;

}  // namespace masa
