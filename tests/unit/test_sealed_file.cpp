// The seal every masa file carries (common/integrity/sealed_file.hpp): a payload round-trips; a
// single bit flipped anywhere, a cut at any length, another kind, a damaged signature are refused
// by name and reason; a file from before the seal loads with a warning naming it, or is refused
// where a signature is required; a signature counts only when its key is trusted. Ed25519 keys:
// a private key readable by others is refused, an existing key is never overwritten.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <random>
#include <stdexcept>
#include <string>

#include "common/integrity/ed25519_keys.hpp"
#include "common/integrity/sealed_file.hpp"
#include "common/integrity/sha256.hpp"
#include "file_mutations.hpp"

namespace masa::integrity {
namespace {

namespace fs = std::filesystem;

constexpr FileKind kToyKind{"masa toy", "TOYFMT01"};
constexpr FileKind kOtherKind{"masa other", "OTHER001"};

fs::path sealedDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("masa_sealed_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string toyPayload(std::size_t n) {
  std::string p = "TOYFMT01";
  std::mt19937_64 rng(7);
  while (p.size() < n) p.push_back(static_cast<char>(rng()));
  return p;
}

std::string sealedBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string sealedRefusal(const std::string& bytes, const FileKind& kind = kToyKind, const ReadRules& rules = {}) {
  try {
    openSealedBytes(bytes, "toy.bin", kind, rules);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(Sha256, MatchesTheStandardTestVector) {
  EXPECT_EQ(toHex(sha256("abc")), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(SealedFile, APayloadRoundTripsThroughAFileWrittenAtomically) {
  const fs::path dir = sealedDir("roundtrip");
  const std::string payload = toyPayload(1000);
  writeSealedFile((dir / "toy.bin").string(), kToyKind, payload);
  EXPECT_FALSE(fs::exists(dir / "toy.bin.tmp"));
  const OpenedFile f = readSealedFile((dir / "toy.bin").string(), kToyKind);
  EXPECT_EQ(f.payload, payload);
  EXPECT_TRUE(f.sealed);
  EXPECT_FALSE(f.signer);
  EXPECT_TRUE(looksLikeKind((dir / "toy.bin").string(), kToyKind));
  EXPECT_FALSE(looksLikeKind((dir / "toy.bin").string(), kOtherKind));
  EXPECT_EQ(sealedKindOf((dir / "toy.bin").string()), "masa toy");
}

// A payload written piece by piece (a character, small writes, one write larger than the writer's
// buffer) gives the very bytes the envelope built in memory gives, at sizes about the buffer's.
TEST(SealedFile, AStreamedWriteGivesTheSameBytesAsTheEnvelopeBuiltInMemory) {
  const fs::path dir = sealedDir("streamed");
  const std::size_t mib = std::size_t{1} << 20;
  for (const std::size_t n : {std::size_t{0}, std::size_t{1}, mib - 8, mib + 1, 3 * mib + 17}) {
    const std::string payload = toyPayload(n).substr(0, n);
    const std::string path = (dir / ("toy" + std::to_string(n) + ".bin")).string();
    writeSealedFileStreamed(path, kToyKind, [&](std::ostream& os) {
      std::size_t at = 0;
      if (n > 0) os.put(payload[at++]);
      for (int i = 0; i < 100 && at + 777 <= n; ++i, at += 777) os.write(payload.data() + at, 777);
      os.write(payload.data() + at, static_cast<std::streamsize>(n - at));
    });
    EXPECT_EQ(sealedBytes(path), sealBytes(kToyKind, payload)) << n << " bytes";
    EXPECT_FALSE(fs::exists(path + ".tmp"));
  }
}

TEST(SealedFile, AStreamedWriteThatThrowsLeavesTheOldFileAndNoTemporary) {
  const fs::path dir = sealedDir("streamed_throw");
  const std::string path = (dir / "toy.bin").string();
  writeSealedFile(path, kToyKind, toyPayload(500));
  const std::string before = sealedBytes(path);
  EXPECT_THROW(writeSealedFileStreamed(path, kToyKind,
                                       [&](std::ostream& os) {
                                         os << toyPayload(3 << 20);
                                         throw std::runtime_error("the payload's writer failed");
                                       }),
               std::runtime_error);
  EXPECT_EQ(sealedBytes(path), before);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

// A full disk: /dev/full refuses every byte, so the write fails with the reason, not silently.
TEST(SealedFile, AStreamedWriteTheDiskRefusesFailsByName) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  const fs::path dir = sealedDir("streamed_full");
  fs::create_symlink("/dev/full", dir / "toy.bin.tmp");
  try {
    writeSealedFileStreamed((dir / "toy.bin").string(), kToyKind, [&](std::ostream& os) { os << toyPayload(3 << 20); });
    ADD_FAILURE() << "a write to a full disk was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("write failed"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "toy.bin"));
}

TEST(SealedFile, EverySingleBitFlipAndEveryCutIsRefusedWithTheFileAndTheReason) {
  const std::string sealed = sealBytes(kToyKind, toyPayload(300));
  for (std::size_t i = 0; i < sealed.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      std::string b = sealed;
      b[i] ^= static_cast<char>(1 << bit);
      const std::string why = sealedRefusal(b);
      ASSERT_NE(why, "") << "byte " << i << " bit " << bit << " flipped was accepted";
      ASSERT_EQ(why.rfind("toy.bin: ", 0), 0u) << why;
    }
  }
  for (std::size_t n = 0; n < sealed.size(); ++n) ASSERT_NE(sealedRefusal(sealed.substr(0, n)), "") << "cut to " << n << " bytes";
  EXPECT_EQ(sealedRefusal(sealed + "x"), "toy.bin: checksum mismatch (file corrupted or truncated: the seal holds 312 bytes, the file 313)");
  std::string flipped = sealed;
  flipped[200] ^= 1;
  EXPECT_EQ(sealedRefusal(flipped), "toy.bin: checksum mismatch (file corrupted or truncated)");
}

TEST(SealedFile, OneKindIsNeverReadAsAnother) {
  const std::string sealed = sealBytes(kOtherKind, toyPayload(100));
  EXPECT_EQ(sealedRefusal(sealed), "toy.bin: a masa other file, not a masa toy file");
  EXPECT_NE(sealedRefusal("OTHER001 and the rest").find("not a masa toy file"), std::string::npos);
}

TEST(SealedFile, AnUnsealedFileLoadsWithAWarningNamingItUnlessASignatureIsRequired) {
  const std::string legacy = toyPayload(200);
  ::testing::internal::CaptureStderr();
  const OpenedFile f = openSealedBytes(legacy, "old/toy.bin", kToyKind);
  const std::string warning = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(f.payload, legacy);
  EXPECT_FALSE(f.sealed);
  EXPECT_NE(warning.find("warning: old/toy.bin: written before masa sealed its files"), std::string::npos) << warning;
  EXPECT_EQ(std::count(warning.begin(), warning.end(), '\n'), 1) << "one line";
  TrustedKeys trusted;
  ReadRules rules;
  rules.require_signed_by = &trusted;
  EXPECT_NE(sealedRefusal(legacy, kToyKind, rules).find("toy.bin: not signed"), std::string::npos);
}

TEST(SealedFile, OnlyASignatureByATrustedKeyIsAcceptedWhereOneIsRequired) {
  const fs::path dir = sealedDir("signed");
  const PublicKeyBytes release = generateKeyPair((dir / "release.key").string(), (dir / "release.pub").string());
  generateKeyPair((dir / "stranger.key").string(), (dir / "stranger.pub").string());
  const TrustedKeys trusted = TrustedKeys::load((dir / "release.pub").string());
  ASSERT_TRUE(trusted.contains(release));
  ReadRules rules;
  rules.require_signed_by = &trusted;
  const std::string path = (dir / "toy.bin").string();
  const std::string payload = toyPayload(500);

  writeSealedFile(path, kToyKind, payload);
  EXPECT_NE(sealedRefusal(sealedBytes(path), kToyKind, rules).find("not signed, and a signature by a trusted key is required"), std::string::npos);

  signSealedFile(path, SigningKey::load((dir / "stranger.key").string()));
  const std::string by_stranger = sealedRefusal(sealedBytes(path), kToyKind, rules);
  EXPECT_NE(by_stranger.find("which is not a trusted key"), std::string::npos) << by_stranger;
  EXPECT_EQ(readSealedFile(path, kToyKind).payload, payload) << "a valid signature by anyone is still an intact file";

  signSealedFile(path, SigningKey::load((dir / "release.key").string()));
  const OpenedFile f = readSealedFile(path, kToyKind, rules);
  EXPECT_EQ(f.payload, payload);
  ASSERT_TRUE(f.signer);
  EXPECT_EQ(*f.signer, release);
  EXPECT_NE(f.describe().find("signed by " + keyFingerprint(release)), std::string::npos);

  // Every bit of a signed file matters, the signature's too, with or without a required signer.
  const std::string signed_bytes = sealedBytes(path);
  for (std::size_t i = 0; i < signed_bytes.size(); i += (i < 80 || i + 120 > signed_bytes.size()) ? 1 : 7) {
    std::string b = signed_bytes;
    b[i] ^= static_cast<char>(1 << (i % 8));
    ASSERT_NE(sealedRefusal(b), "") << "byte " << i;
  }
  // A directory of trusted keys holds every *.pub in it.
  const TrustedKeys both = TrustedKeys::load(dir.string());
  EXPECT_EQ(both.keys().size(), 2u);
}

TEST(SealedFile, KeysAreFilesThatAreNeverOverwrittenAndAPrivateKeyOthersMayReadIsRefused) {
  const fs::path dir = sealedDir("keys");
  generateKeyPair((dir / "a.key").string(), (dir / "a.pub").string());
  struct stat st {};
  ASSERT_EQ(::stat((dir / "a.key").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_THROW(generateKeyPair((dir / "a.key").string(), (dir / "b.pub").string()), std::runtime_error);
  fs::permissions(dir / "a.key", fs::perms::group_read, fs::perm_options::add);
  try {
    SigningKey::load((dir / "a.key").string());
    FAIL() << "a group-readable private key was loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("readable by others"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "junk.pub") << "not a key\n";
  EXPECT_THROW(TrustedKeys::load((dir / "junk.pub").string()), std::runtime_error);
  // docs/inputs.md gap 9: whoever may write a trusted key, or their directory, could add their own.
  EXPECT_NO_THROW(TrustedKeys::load((dir / "a.pub").string()));
  fs::remove(dir / "junk.pub");
  fs::permissions(dir / "a.pub", fs::perms::others_write, fs::perm_options::add);
  for (const fs::path& p : {dir / "a.pub", dir}) {
    try {
      TrustedKeys::load(p.string());
      ADD_FAILURE() << "a trusted key others may write was loaded from " << p;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("others may write it"), std::string::npos) << e.what();
    }
  }
  fs::permissions(dir / "a.pub", fs::perms::others_write, fs::perm_options::remove);
  fs::permissions(dir, fs::perms::group_write, fs::perm_options::add);
  EXPECT_THROW(TrustedKeys::load(dir.string()), std::runtime_error) << "a directory others may write";
}

// Random damage of every kind: no crash, and nothing but the intact bytes accepted.
TEST(SealedFile, RandomMutationsAreRefusedUnlessTheyLeaveTheBytesAsTheyWere) {
  const std::string sealed = sealBytes(kToyKind, toyPayload(2000));
  std::mt19937_64 rng(20261203);
  int refused = 0, unchanged = 0;
  for (int i = 0; i < 2000; ++i) {
    const fuzz::FileMutation m = fuzz::mutateFile(sealed, rng);
    if (m.bytes == sealed) {
      ++unchanged;
      continue;
    }
    ASSERT_NE(sealedRefusal(m.bytes), "") << "mutation " << i << " (" << m.what << ") accepted";
    ++refused;
  }
  EXPECT_GT(refused, 1900);
}

}  // namespace
}  // namespace masa::integrity
