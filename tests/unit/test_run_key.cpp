// The run key's file: made once with mode 0600, read back the same, refused when malformed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <sys/stat.h>

#include "common/transport/run_key.hpp"
#include "test_temp_dir.hpp"

namespace masa::transport {
namespace {

namespace fs = std::filesystem;

fs::path freshKeyDir(const std::string& name) { return masa::testing::freshTempDir("masa_test_run_key_" + name); }

std::string errorOf(const std::string& path) {
  try {
    readRunKey(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(RunKey, IsMadeOnceWithModeSixHundredAndReadBackTheSame) {
  const fs::path dir = freshKeyDir("make");
  const std::string path = (dir / "run.key").string();
  const RunKey made = readOrCreateRunKey(path);
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(fs::file_size(path), 65u) << "64 hex digits and a newline";
  EXPECT_EQ(readRunKey(path), made);
  EXPECT_EQ(readOrCreateRunKey(path), made) << "an existing key is kept";
  EXPECT_NE(RunKey::random(), made);
  EXPECT_EQ(made.id().size(), 8u);
  EXPECT_NE(made.id(), RunKey::random().id());
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1) << "no temporary file left";
  fs::remove_all(dir);
}

TEST(RunKey, AMalformedOrMissingFileIsRefusedWithItsPath) {
  const fs::path dir = freshKeyDir("bad");
  const std::string short_key = (dir / "short.key").string(), not_hex = (dir / "not_hex.key").string();
  std::ofstream(short_key) << "abcd\n";
  std::ofstream(not_hex) << std::string(63, 'a') << "g\n";
  EXPECT_NE(errorOf(short_key).find(short_key + ": expected 64 hex digits"), std::string::npos) << errorOf(short_key);
  EXPECT_NE(errorOf(not_hex).find("not hex digits"), std::string::npos) << errorOf(not_hex);
  const std::string missing = (dir / "missing.key").string();
  EXPECT_NE(errorOf(missing).find(missing + ": cannot read"), std::string::npos) << errorOf(missing);
  fs::remove_all(dir);
}

TEST(RunKey, UpperCaseHexReadsAsTheSameKey) {
  const fs::path dir = freshKeyDir("case");
  const std::string lower = (dir / "lower.key").string(), upper = (dir / "upper.key").string();
  std::ofstream(lower) << std::string(32, 'a') << std::string(32, '7') << "\n";
  std::ofstream(upper) << std::string(32, 'A') << std::string(32, '7');
  fs::permissions(lower, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  fs::permissions(upper, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  const RunKey k = readRunKey(lower);
  EXPECT_EQ(k.bytes[0], 0xaa);
  EXPECT_EQ(k.bytes[31], 0x77);
  EXPECT_EQ(readRunKey(upper), k);
  fs::remove_all(dir);
}

// docs/inputs.md gap 9: a run key others may read was only warned about; it is refused now.
TEST(RunKey, AKeyOthersMayReadIsRefusedSayingHowToFixIt) {
  const fs::path dir = freshKeyDir("mode");
  const std::string path = (dir / "run.key").string();
  readOrCreateRunKey(path);
  fs::permissions(path, fs::perms::others_read, fs::perm_options::add);
  EXPECT_NE(errorOf(path).find("has mode 0604: others may read it"), std::string::npos) << errorOf(path);
  EXPECT_NE(errorOf(path).find("chmod 600 " + path), std::string::npos);
  fs::permissions(path, fs::perms::others_read, fs::perm_options::remove);
  EXPECT_EQ(errorOf(path), "") << "mode 0600 reads";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace masa::transport
