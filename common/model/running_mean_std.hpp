// Running mean and variance of a stream of batches (Chan et al.'s parallel update, in double),
// used to normalize observations and value targets.
//
// With a symmetry attached, every batch is counted together with its whole group orbit {T_i x},
// then the mean is projected onto the invariant subspace ((1/N) sum_i T_i m) and variances are
// averaged within each orbit class. The normalizer then commutes with every T_i, so it keeps the
// policy equivariant and the critic invariant.
#pragma once

#include <iosfwd>
#include <vector>

#include "common/core/types.hpp"
#include "common/symmetry/sparse_map.hpp"

namespace masa::model {

template <typename S>
class RunningMeanStd {
 public:
  explicit RunningMeanStd(int dim, double epsilon = 1e-5);

  void setSymmetry(const std::vector<sym::SparseMap>& transforms, const std::vector<int>& classes);
  bool symmetric() const { return !transforms_.empty(); }

  void update(const ConstMatRef<S>& batch);  // dim x B = mergeMoments(batchMoments(batch))
  // The two halves of update(), for data-parallel learners that sum the moments of their shares of
  // one batch across ranks before merging: [sum (dim), sum of squares (dim), count], in double,
  // over the batch or its whole orbit when symmetric. Summable: the moments of a batch are the sum
  // of its parts' moments.
  Eigen::VectorXd batchMoments(const ConstMatRef<S>& batch);
  void mergeMoments(const Eigen::VectorXd& moments);
  void normalize(const ConstMatRef<S>& in, MatRef<S> out) const;    // (x - mean) / sqrt(var + eps)
  void denormalize(const ConstMatRef<S>& in, MatRef<S> out) const;  // x * sqrt(var + eps) + mean

  int dim() const { return dim_; }
  double count() const { return count_; }
  const Eigen::VectorXd& mean() const { return mean_eff_; }
  const Eigen::VectorXd& var() const { return var_eff_; }
  // What normalize() applies, in S: out = (x - shift()) * invScale(). Exporters read these so that
  // they reproduce the normalizer to the bit (epsilon included).
  const Vec<S>& shift() const { return shift_; }
  const Vec<S>& invScale() const { return inv_scale_; }

  // Replaces the statistics with a broadcast mean and std (std already includes epsilon, > 0), as
  // an actor receives them from the learner; used as given, without symmetry projection.
  void setMeanStd(const float* mean, const float* std);

  void save(std::ostream& os) const;
  void load(std::istream& is);  // throws std::runtime_error on a dimension mismatch or truncation

 private:
  void refreshEffective();

  int dim_;
  double epsilon_;
  double count_;
  Eigen::VectorXd mean_, var_;          // raw running statistics (of the orbit, when symmetric)
  Eigen::VectorXd mean_eff_, var_eff_;  // projected statistics actually used
  Vec<S> shift_, scale_, inv_scale_;    // cached in S: mean, sqrt(var + eps), and its inverse
  std::vector<sym::SparseMap> transforms_;
  std::vector<int> classes_;
  Mat<S> orbit_scratch_;
};

}  // namespace masa::model
