#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

#include "common/nn/mlp.hpp"
#include "common/nn/serialize.hpp"

namespace masa::nn {
namespace {

namespace fs = std::filesystem;

template <typename S>
struct Policy {
  ParameterSet<S> params;
  std::unique_ptr<Mlp<S>> mlp;
  Policy(std::vector<int> hidden, std::uint64_t seed) {
    MlpShape shape;
    shape.input = 6;
    shape.hidden = std::move(hidden);
    shape.output = 3;
    mlp = std::make_unique<Mlp<S>>(params, "policy", shape);
    params.finalize();
    Rng rng(seed);
    mlp->initialize(rng);
  }
};

// A path unique to this test and process, removed afterwards.
class SerializeFile : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = (fs::temp_directory_path() /
             ("masa_" + std::string(info->name()) + "_" + std::to_string(::getpid()) + ".bin"))
                .string();
  }
  void TearDown() override { fs::remove(path_); }
  std::string loadError(ParameterSet<float>& p) {
    try {
      loadParameters(p, path_);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }
  std::string path_;
};

TEST_F(SerializeFile, SaveThenLoadIsBitwiseIdenticalInParametersAndOutputs) {
  Policy<float> saved({16, 8}, 1), loaded({16, 8}, 2);
  ASSERT_NE(saved.params.values(), loaded.params.values());
  saveParameters(saved.params, path_);
  loadParameters(loaded.params, path_);
  EXPECT_EQ(std::memcmp(saved.params.values().data(), loaded.params.values().data(),
                        sizeof(float) * saved.params.size()),
            0);
  const Mat<float> x = Mat<float>::Random(6, 13);
  const Mat<float> y_saved = saved.mlp->forward(x);
  const Mat<float> y_loaded = loaded.mlp->forward(x);
  EXPECT_EQ(std::memcmp(y_saved.data(), y_loaded.data(), sizeof(float) * y_saved.size()), 0);
}

TEST(Serialize, StreamRoundTripInDoubleKeepsEveryBit) {
  Policy<double> saved({5}, 3), loaded({5}, 4);
  saved.params.values()(0) = -0.0;
  saved.params.values()(1) = 1e-310;  // subnormal
  std::stringstream ss;
  saveParameters(saved.params, ss);
  loadParameters(loaded.params, ss);
  EXPECT_EQ(std::memcmp(saved.params.values().data(), loaded.params.values().data(),
                        sizeof(double) * saved.params.size()),
            0);
}

TEST_F(SerializeFile, LoadingIntoADifferentShapeNamesTheFirstDifferingSegment) {
  Policy<float> saved({8, 6}, 1), other({8, 5}, 1);
  saveParameters(saved.params, path_);
  const Vec<float> before = other.params.values();
  EXPECT_EQ(loadError(other.params), path_ + ": segment 3 is 'policy.layer1.weight' 6x8 in the file but "
                                             "'policy.layer1.weight' 5x8 in the model");
  EXPECT_EQ(other.params.values(), before);  // a failed load changes nothing
}

TEST_F(SerializeFile, LoadingIntoADeeperOrShallowerModelNamesTheSegment) {
  // hidden {8} and {8, 3} agree on the first four segments (the 3-wide hidden layer has the shape
  // of the 3-wide output layer), so only the count tells them apart.
  Policy<float> shallow({8}, 1), deeper({8, 3}, 1);
  saveParameters(deeper.params, path_);
  EXPECT_EQ(loadError(shallow.params),
            path_ + ": segment 5 is 'policy.layer2.weight' 3x3 in the file but the model has only 4 segments");
  saveParameters(shallow.params, path_);
  EXPECT_EQ(loadError(deeper.params), path_ + ": the file has 4 segments but the model has 6, starting with segment 5 "
                                               "'policy.layer2.weight' 3x3");
}

TEST_F(SerializeFile, TruncatedFileThrows) {
  Policy<float> saved({8}, 1), loaded({8}, 2);
  saveParameters(saved.params, path_);
  const auto full = fs::file_size(path_);
  fs::resize_file(path_, full - 1);
  EXPECT_NE(loadError(loaded.params).find("file ends while reading the values"), std::string::npos);
  fs::resize_file(path_, 20);  // inside the first segment's header
  EXPECT_NE(loadError(loaded.params).find("file ends"), std::string::npos);
}

TEST_F(SerializeFile, WrongMagicThrows) {
  Policy<float> saved({8}, 1);
  saveParameters(saved.params, path_);
  {
    std::fstream f(path_, std::ios::in | std::ios::out | std::ios::binary);
    f.write("XASA", 4);
  }
  EXPECT_EQ(loadError(saved.params), path_ + ": not a masa parameter file (bad magic)");
}

TEST_F(SerializeFile, ScalarTypeMismatchThrows) {
  Policy<double> saved({8}, 1);
  saveParameters(saved.params, path_);
  Policy<float> loaded({8}, 1);
  EXPECT_NE(loadError(loaded.params).find("scalar size is 8 bytes in the file but 4 in the model"), std::string::npos);
}

TEST(Serialize, MissingFileThrowsNamingThePath) {
  Policy<float> p({4}, 1);
  const std::string path = "/nonexistent_dir_masa/model.bin";
  try {
    loadParameters(p.params, path);
    FAIL() << "loading a missing file succeeded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_THROW(saveParameters(p.params, path), std::runtime_error);
}

}  // namespace
}  // namespace masa::nn
