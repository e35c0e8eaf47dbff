// Keys and rosters that prove who wrote them (issue #55, item 4; common/integrity/owned_file.hpp):
// a roster another user owns, a key or roster in a directory others may write, a symbolic link and
// a FIFO in the key's place are refused, each naming the file and why; and a signed message longer
// than its sender's role sends is refused before a byte of it is hashed (message_sign.hpp).
// Before the fix each failed: Roster::load and SigningKey::load checked the file's mode alone (a
// stat, then a second open by name), and MessageVerifier::open hashed whatever size came.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "common/integrity/ed25519_keys.hpp"
#include "common/integrity/owned_file.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/message_sign.hpp"
#include "common/transport/roster.hpp"

namespace masa::transport {
namespace {

namespace fs = std::filesystem;

constexpr uid_t kOwnedFilesNobodyUid = 65534;

// A directory of this test's own (mode 0700), removed at the end.
struct OwnedFilesDir {
  fs::path dir;
  explicit OwnedFilesDir(const std::string& name)
      : dir(fs::temp_directory_path() / ("masa_test_owned_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    ::chmod(dir.c_str(), 0700);
  }
  ~OwnedFilesDir() { fs::remove_all(dir); }
};

// A roster of one robot with a fresh key, written to `dir`/roster (mode 0644); its signer.
std::shared_ptr<MessageSigner> writeRobotRoster(const fs::path& dir) {
  const std::string stem = (dir / "robot0").string();
  Roster roster(std::string("test"));
  roster.add({Role::kRobot, 0}, integrity::generateKeyPair(stem + ".key", stem + ".pub"), defaultChannels(Role::kRobot));
  {
    std::ofstream(dir / "roster") << roster.format();
  }
  ::chmod((dir / "roster").c_str(), 0644);
  return MessageSigner::load(stem + ".key", {Role::kRobot, 0}, Roster::load((dir / "roster").string()));
}

void expectOwnedFileRefused(const std::function<void()>& load, const std::string& why, const std::string& what) {
  try {
    load();
    ADD_FAILURE() << what << " was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << what << ": " << e.what();
  }
}

TEST(OwnedFiles, ARosterOwnedByAnotherUserIsRefused) {
  if (::geteuid() != 0) GTEST_SKIP() << "giving a file to another user needs root";
  OwnedFilesDir d("other_user");
  writeRobotRoster(d.dir);
  const std::string roster = (d.dir / "roster").string();
  ASSERT_NO_THROW(Roster::load(roster));
  ASSERT_EQ(::chown(roster.c_str(), kOwnedFilesNobodyUid, static_cast<gid_t>(-1)), 0);
  expectOwnedFileRefused([&] { Roster::load(roster); }, "belongs to user 65534", "a roster owned by nobody");
  // Its key alike: a private key another user owns is theirs, whatever its mode.
  const std::string key = (d.dir / "robot0.key").string();
  ASSERT_EQ(::chown(key.c_str(), kOwnedFilesNobodyUid, static_cast<gid_t>(-1)), 0);
  expectOwnedFileRefused([&] { integrity::SigningKey::load(key); }, "belongs to user 65534", "a key owned by nobody");
  // And a directory another user owns: they may rename our file away and put theirs in its place.
  ASSERT_EQ(::chown(roster.c_str(), 0, static_cast<gid_t>(-1)), 0);
  ASSERT_EQ(::chown(d.dir.c_str(), kOwnedFilesNobodyUid, static_cast<gid_t>(-1)), 0);
  expectOwnedFileRefused([&] { Roster::load(roster); }, "its directory", "a roster in nobody's directory");
  ASSERT_EQ(::chown(d.dir.c_str(), 0, static_cast<gid_t>(-1)), 0);
}

TEST(OwnedFiles, AKeyOrRosterInAGroupWritableDirectoryIsRefused) {
  OwnedFilesDir d("group_writable");
  writeRobotRoster(d.dir);
  const std::string key = (d.dir / "robot0.key").string(), roster = (d.dir / "roster").string();
  ASSERT_NO_THROW(integrity::SigningKey::load(key));
  for (const mode_t mode : {0770, 0707, 0775}) {
    ::chmod(d.dir.c_str(), mode);
    expectOwnedFileRefused([&] { integrity::SigningKey::load(key); }, "others may write its directory", "a key in a writable directory");
    expectOwnedFileRefused([&] { Roster::load(roster); }, "others may write its directory", "a roster in a writable directory");
  }
  ::chmod(d.dir.c_str(), 0755);  // others may read the directory, not write it: fine
  EXPECT_NO_THROW(integrity::SigningKey::load(key));
  EXPECT_NO_THROW(Roster::load(roster));
}

TEST(OwnedFiles, ALinkOrAFifoInTheKeysPlaceIsRefusedWithoutHanging) {
  OwnedFilesDir d("link");
  writeRobotRoster(d.dir);
  const fs::path link = d.dir / "linked.key", fifo = d.dir / "fifo.key";
  fs::create_symlink(d.dir / "robot0.key", link);
  expectOwnedFileRefused([&] { integrity::SigningKey::load(link.string()); }, "symbolic link", "a link to a key");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expectOwnedFileRefused([&] { integrity::SigningKey::load(fifo.string()); }, "not a regular file", "a FIFO");
}

TEST(OwnedFiles, AnOversizedSignedMessageIsRefusedBeforeItIsHashed) {
  OwnedFilesDir d("oversized");
  const std::shared_ptr<MessageSigner> robot = writeRobotRoster(d.dir);
  MessageVerifier verifier(std::make_shared<Roster>(Roster::load((d.dir / "roster").string())), 0);
  const auto sealed = [&](std::size_t size) {
    std::vector<uint8_t> bytes(size + kSigTrailerBytes, 0x5a);
    robot->seal(kRobotStateChannel, bytes.data(), static_cast<int>(size), bytes.data() + size);
    return bytes;
  };
  const std::size_t limit = static_cast<std::size_t>(maxSignedMessageBytes(Role::kRobot));
  ASSERT_LT(limit, std::size_t{1} << 20) << "a robot's limit is far below a training message's";
  // Signed by the robot's own key, on its own channel: only its size is wrong.
  const std::vector<uint8_t> big = sealed(limit + 1);
  const OpenedMessage refused = verifier.open(kRobotStateChannel, big.data(), static_cast<int>(big.size()));
  EXPECT_EQ(refused.verdict, WireVerdict::kOverLimit);
  EXPECT_EQ(verifier.messagesHashed(), 0) << "the oversized message was hashed before it was refused";
  const std::vector<uint8_t> at_limit = sealed(limit);
  EXPECT_EQ(verifier.open(kRobotStateChannel, at_limit.data(), static_cast<int>(at_limit.size())).verdict, WireVerdict::kOk);
  EXPECT_EQ(verifier.messagesHashed(), 1);
}

}  // namespace
}  // namespace masa::transport
