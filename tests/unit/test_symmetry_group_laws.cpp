// Group laws of every shipped spec in configs/specs, for observations and actions alike.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>

#include "common/symmetry/symmetry_spec.hpp"

namespace masa::sym {
namespace {

constexpr double kTol = 1e-12;

std::vector<std::string> shippedSpecs() {
  std::vector<std::string> paths;
  const std::filesystem::path dir = std::filesystem::path(MASA_SOURCE_DIR) / "configs" / "specs";
  if (std::filesystem::is_directory(dir))
    for (const auto& f : std::filesystem::directory_iterator(dir))
      if (f.path().extension() == ".yaml") paths.push_back(f.path().string());
  std::sort(paths.begin(), paths.end());
  return paths;
}

double maxAbs(const Eigen::MatrixXd& m) { return m.size() == 0 ? 0.0 : m.cwiseAbs().maxCoeff(); }

class SymmetryGroupLaws : public ::testing::TestWithParam<std::string> {
 protected:
  // Both the observation and the action maps, with a label for failure messages.
  struct Maps {
    const char* what;
    int dim;
    std::vector<Eigen::MatrixXd> t, inv;
  };
  std::vector<Maps> maps() const {
    const SymmetrySpec spec = SymmetrySpec::load(GetParam());
    Maps obs{"observation", spec.obsDim(), {}, {}}, act{"action", spec.actDim(), {}, {}};
    for (int i = 0; i < spec.numAgents(); ++i) {
      obs.t.push_back(spec.obsTransform(i).toDense());
      obs.inv.push_back(spec.obsInverse(i).toDense());
      act.t.push_back(spec.actTransform(i).toDense());
      act.inv.push_back(spec.actInverse(i).toDense());
    }
    return {obs, act};
  }
};

TEST_P(SymmetryGroupLaws, IdentityElementIsIdentityMatrix) {
  for (const Maps& m : maps())
    EXPECT_LT(maxAbs(m.t[0] - Eigen::MatrixXd::Identity(m.dim, m.dim)), kTol) << m.what;
}

TEST_P(SymmetryGroupLaws, CompositionFollowsCyclicGroup) {
  for (const Maps& m : maps()) {
    const int n = static_cast<int>(m.t.size());
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        EXPECT_LT(maxAbs(m.t[i] * m.t[j] - m.t[(i + j) % n]), kTol) << m.what << " T_" << i << " T_" << j;
  }
}

TEST_P(SymmetryGroupLaws, InverseUndoesTransform) {
  for (const Maps& m : maps())
    for (std::size_t i = 0; i < m.t.size(); ++i)
      EXPECT_LT(maxAbs(m.inv[i] * m.t[i] - Eigen::MatrixXd::Identity(m.dim, m.dim)), kTol) << m.what << " i=" << i;
}

TEST_P(SymmetryGroupLaws, EveryTransformIsOrthogonal) {
  for (const Maps& m : maps())
    for (std::size_t i = 0; i < m.t.size(); ++i)
      EXPECT_LT(maxAbs(m.t[i].transpose() * m.t[i] - Eigen::MatrixXd::Identity(m.dim, m.dim)), kTol)
          << m.what << " i=" << i;
}

TEST_P(SymmetryGroupLaws, NamesAndClassesCoverEveryDimension) {
  const SymmetrySpec spec = SymmetrySpec::load(GetParam());
  EXPECT_EQ(static_cast<int>(spec.obsNames().size()), spec.obsDim());
  EXPECT_EQ(static_cast<int>(spec.actNames().size()), spec.actDim());
  EXPECT_EQ(static_cast<int>(spec.obsClasses().size()), spec.obsDim());
  EXPECT_EQ(static_cast<int>(spec.actClasses().size()), spec.actDim());
  // Names are unique, so every dimension can be addressed by name.
  std::map<std::string, int> seen;
  for (const auto& n : spec.obsNames()) EXPECT_EQ(seen[n]++, 0) << "duplicate name " << n;
}

std::string specName(const ::testing::TestParamInfo<std::string>& info) {
  return std::filesystem::path(info.param).stem().string();
}

INSTANTIATE_TEST_SUITE_P(ShippedSpecs, SymmetryGroupLaws, ::testing::ValuesIn(shippedSpecs()), specName);

// The dimensions the rest of masa relies on (paper appendix, with the ant's documented deviation).
TEST(SymmetryShippedSpecs, EveryTaskHasItsSpecWithExpectedDimensions) {
  const std::map<std::string, std::pair<int, int>> expected{
      {"humanoid_tightrope", {74, 21}}, {"humanoid_dribbling", {80, 21}}, {"trifinger_lift", {41, 9}},
      {"a1_beam", {47, 12}},            {"ant_acrobatic", {58, 8}},
  };
  const std::vector<std::string> files = shippedSpecs();
  for (const auto& [task, dims] : expected) {
    const std::string path = std::string(MASA_SOURCE_DIR) + "/configs/specs/" + task + ".yaml";
    ASSERT_TRUE(std::find(files.begin(), files.end(), path) != files.end()) << "missing " << path;
    const SymmetrySpec spec = SymmetrySpec::load(path);
    EXPECT_EQ(spec.name(), task);
    EXPECT_EQ(spec.obsDim(), dims.first) << task;
    EXPECT_EQ(spec.actDim(), dims.second) << task;
  }
}

}  // namespace
}  // namespace masa::sym
