// The fixture of the text readers' fuzz tests (docs/inputs.md gap 4): a scratch copy of configs/
// and fuzz(file, name, seed, read), which damages a file with file_mutations.hpp and requires the
// reader to accept it within its checks or to throw naming the file, within a time bound.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <unistd.h>

#include "file_mutations.hpp"

namespace masa::test {

namespace fs = std::filesystem;

inline const std::string kConfigs = MASA_SOURCE_DIR "/configs";
inline constexpr int kMutationsPerFile = 25;
inline constexpr double kSecondsPerRead = 2.0;

inline std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline void writeAll(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

// A scratch copy of configs/ (and the models it points at stay where they are: paths in the
// configs are relative to the source tree's configs' parent, so the copy sits beside a link).
class DamagedText : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("masa_text_fuzz_" + std::to_string(::getpid()) + "_" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
    fs::copy(kConfigs, root_ / "configs", fs::copy_options::recursive);
    for (const char* linked : {"tasks", "tests"}) fs::create_directory_symlink(MASA_SOURCE_DIR "/" + std::string(linked), root_ / linked);
  }
  void TearDown() override { fs::remove_all(root_); }

  // Mutates `file` kMutationsPerFile times (restoring it after each) and calls `read`: it must
  // return or throw a std::exception whose message holds `name`, within the time bound.
  void fuzz(const fs::path& file, const std::string& name, uint64_t seed, const std::function<void()>& read) {
    const std::string original = readAll(file);
    std::mt19937_64 rng(seed);
    for (int i = 0; i < kMutationsPerFile; ++i) {
      const masa::fuzz::FileMutation m = masa::fuzz::mutateFile(original, rng);
      writeAll(file, m.bytes);
      const auto t0 = std::chrono::steady_clock::now();
      try {
        read();
        ++accepted_;
      } catch (const std::exception& e) {
        ++refused_;
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos)
            << file.filename() << ", " << m.what << ": the error does not name the file: " << e.what();
      }
      EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), kSecondsPerRead)
          << file.filename() << ", " << m.what;
    }
    writeAll(file, original);
  }

  fs::path root_;
  int accepted_ = 0, refused_ = 0;
};

}  // namespace masa::test
