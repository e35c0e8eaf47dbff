// SASA-data: the augmented dataset holds every transition and its N-1 images, each image exactly
// the spec's T_i applied to o, a and o', with reward and flags unchanged.
#include <gtest/gtest.h>

#include "learner/offline/symmetry_augmentation.hpp"
#include "offline_test_support.hpp"

namespace masa::offline {
namespace {

void expectImagesOf(const sym::SymmetrySpec& spec) {
  Rng rng(3);
  const auto data = test::randomDataset(spec, 4, 5, rng);
  const auto aug = augmentWithSymmetricImages(data, spec);
  const int n_images = spec.numAgents();
  const int64_t n = data.size();
  ASSERT_EQ(aug.size(), n * n_images) << spec.name();
  EXPECT_NO_THROW(aug.validate());
  ASSERT_EQ(aug.episodes.size(), data.episodes.size() * n_images);
  for (int i = 0; i < n_images; ++i) {
    // Image i by the dense matrix of T_i, independently of SparseMap::apply.
    const Eigen::MatrixXf to = spec.obsTransform(i).toDense().cast<float>();
    const Eigen::MatrixXf ta = spec.actTransform(i).toDense().cast<float>();
    for (int64_t k = 0; k < n; ++k) {
      const int64_t c = i * n + k;
      EXPECT_LT((aug.obs.col(c) - to * data.obs.col(k)).cwiseAbs().maxCoeff(), 1e-6) << "image " << i << " column " << k;
      EXPECT_LT((aug.next_obs.col(c) - to * data.next_obs.col(k)).cwiseAbs().maxCoeff(), 1e-6) << i << " " << k;
      EXPECT_LT((aug.actions.col(c) - ta * data.actions.col(k)).cwiseAbs().maxCoeff(), 1e-6) << i << " " << k;
      EXPECT_EQ(aug.rewards(c), data.rewards(k));
      EXPECT_EQ(aug.terminals[c], data.terminals[k]);
      EXPECT_EQ(aug.timeouts[c], data.timeouts[k]);
    }
    for (size_t e = 0; e < data.episodes.size(); ++e) {
      const auto& img = aug.episodes[i * data.episodes.size() + e];
      EXPECT_EQ(img.start, data.episodes[e].start + i * n);
      EXPECT_EQ(img.length, data.episodes[e].length);
      EXPECT_EQ(img.episode_id / n_images, data.episodes[e].episode_id);
      EXPECT_EQ(img.episode_id % n_images, i);
    }
  }
  // Non-identity images really moved the data (a no-op augmentation would pass the checks above
  // only if T_i were the identity).
  if (n_images > 1) {
    EXPECT_GT((aug.obs.middleCols(n, n) - data.obs).norm(), 1.0);
  }
}

TEST(OfflineAugmentation, HoldsEveryTransitionAndItsImagesForMirrorC3AndC4) {
  expectImagesOf(test::spec(test::kMirrorSpec, "mirror"));
  expectImagesOf(test::spec(test::kC3Spec, "c3"));
  expectImagesOf(test::spec(test::kC4Spec, "c4"));
}

TEST(OfflineAugmentation, RejectsADatasetOfOtherDimensions) {
  Rng rng(4);
  const auto data = test::randomDataset(test::spec(test::kC3Spec, "c3"), 2, 3, rng);
  EXPECT_THROW(augmentWithSymmetricImages(data, test::spec(test::kMirrorSpec, "mirror")), std::runtime_error);
}

}  // namespace
}  // namespace masa::offline
