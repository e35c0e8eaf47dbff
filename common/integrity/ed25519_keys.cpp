#include "common/integrity/ed25519_keys.hpp"

#include <fcntl.h>
#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "common/integrity/owned_file.hpp"
#include "common/integrity/sha256.hpp"

namespace masa::integrity {
namespace fs = std::filesystem;

struct SigningKey::Pkey {
  EVP_PKEY* key = nullptr;
  ~Pkey() { EVP_PKEY_free(key); }
};

namespace {

using Bio = std::unique_ptr<BIO, decltype(&BIO_free)>;
using PkeyPtr = std::unique_ptr<EVP_PKEY, decltype(&EVP_PKEY_free)>;
using MdCtx = std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)>;

PublicKeyBytes rawPublicKey(EVP_PKEY* key, const std::string& where) {
  PublicKeyBytes raw{};
  std::size_t len = raw.size();
  if (EVP_PKEY_get_raw_public_key(key, raw.data(), &len) != 1 || len != raw.size())
    throw std::runtime_error(where + ": cannot read the raw Ed25519 public key");
  return raw;
}

bool isEd25519(EVP_PKEY* key) { return key && EVP_PKEY_is_a(key, "ED25519") == 1; }

// Writes `pem` into a file made for it (O_EXCL: an existing key is never overwritten).
void writeNewFile(const std::string& path, const std::string& text, mode_t mode) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL, mode);
  if (fd < 0) throw std::runtime_error(path + ": cannot create (" + std::strerror(errno) + "; an existing key is never overwritten)");
  const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) throw std::runtime_error(path + ": write failed");
}

std::string pemOf(EVP_PKEY* key, bool private_part) {
  Bio bio(BIO_new(BIO_s_mem()), &BIO_free);
  const int ok = private_part ? PEM_write_bio_PrivateKey(bio.get(), key, nullptr, nullptr, 0, nullptr, nullptr)
                              : PEM_write_bio_PUBKEY(bio.get(), key);
  if (!bio || ok != 1) throw std::runtime_error("Ed25519: cannot encode the key as PEM");
  char* data = nullptr;
  const long n = BIO_get_mem_data(bio.get(), &data);
  return std::string(data, static_cast<std::size_t>(n));
}

}  // namespace

std::string keyFingerprint(const PublicKeyBytes& key) {
  const Digest d = sha256(std::string_view(reinterpret_cast<const char*>(key.data()), key.size()));
  return "ed25519:" + toHex(d.data(), 8);
}

SigningKey::SigningKey(std::shared_ptr<Pkey> key) : key_(std::move(key)) { public_ = rawPublicKey(key_->key, "signing key"); }

SigningKey SigningKey::load(const std::string& path) {
  if (!fs::exists(path)) throw std::runtime_error(path + ": no such private key file");
  // Opened once, owner, mode and directory checked on the open file (owned_file.hpp).
  const std::string pem = readOwnedFile(path, "private key", FileSecrecy::kSecret);
  Bio bio(BIO_new_mem_buf(pem.data(), static_cast<int>(pem.size())), &BIO_free);
  if (!bio) throw std::runtime_error(path + ": cannot open the private key");
  auto pkey = std::make_shared<Pkey>();
  pkey->key = PEM_read_bio_PrivateKey(bio.get(), nullptr, nullptr, nullptr);
  if (!isEd25519(pkey->key)) throw std::runtime_error(path + ": not a PEM Ed25519 private key");
  return SigningKey(std::move(pkey));
}

SigningKey SigningKey::generate() {
  auto pkey = std::make_shared<Pkey>();
  pkey->key = EVP_PKEY_Q_keygen(nullptr, nullptr, "ED25519");
  if (!isEd25519(pkey->key)) throw std::runtime_error("Ed25519: key generation failed");
  return SigningKey(std::move(pkey));
}

SignatureBytes SigningKey::sign(std::string_view message) const {
  SignatureBytes sig{};
  std::size_t len = sig.size();
  MdCtx ctx(EVP_MD_CTX_new(), &EVP_MD_CTX_free);
  if (!ctx || EVP_DigestSignInit(ctx.get(), nullptr, nullptr, nullptr, key_->key) != 1 ||
      EVP_DigestSign(ctx.get(), sig.data(), &len, reinterpret_cast<const unsigned char*>(message.data()), message.size()) != 1 ||
      len != sig.size())
    throw std::runtime_error("Ed25519: signing failed");
  return sig;
}

PublicKeyBytes generateKeyPair(const std::string& private_path, const std::string& public_path) {
  PkeyPtr key(EVP_PKEY_Q_keygen(nullptr, nullptr, "ED25519"), &EVP_PKEY_free);
  if (!key) throw std::runtime_error("Ed25519: key generation failed");
  if (fs::exists(public_path)) throw std::runtime_error(public_path + ": exists; an existing key is never overwritten");
  writeNewFile(private_path, pemOf(key.get(), true), 0600);
  writeNewFile(public_path, pemOf(key.get(), false), 0644);
  return rawPublicKey(key.get(), public_path);
}

bool verifySignature(const PublicKeyBytes& key, std::string_view message, const SignatureBytes& signature) {
  PkeyPtr pkey(EVP_PKEY_new_raw_public_key(EVP_PKEY_ED25519, nullptr, key.data(), key.size()), &EVP_PKEY_free);
  MdCtx ctx(EVP_MD_CTX_new(), &EVP_MD_CTX_free);
  if (!pkey || !ctx || EVP_DigestVerifyInit(ctx.get(), nullptr, nullptr, nullptr, pkey.get()) != 1) return false;
  return EVP_DigestVerify(ctx.get(), signature.data(), signature.size(),
                          reinterpret_cast<const unsigned char*>(message.data()), message.size()) == 1;
}

bool TrustedKeys::contains(const PublicKeyBytes& key) const {
  return std::find(keys_.begin(), keys_.end(), key) != keys_.end();
}

namespace {
// Anyone who can write a trusted key file, or the directory of them, can make their own key
// trusted: refuse either, as ssh refuses an authorized_keys others may write.
void refuseWritableByOthers(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || (st.st_mode & 022) == 0) return;
  char mode[8];
  std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
  throw std::runtime_error(path + ": others may write it (mode " + mode +
                           "), so anyone could add a key that is then trusted (chmod go-w " + path + ")");
}
}  // namespace

TrustedKeys TrustedKeys::load(const std::string& path) {
  refuseWritableByOthers(path);
  std::vector<std::string> files;
  if (fs::is_directory(path)) {
    for (const auto& entry : fs::directory_iterator(path))
      if (entry.path().extension() == ".pub") files.push_back(entry.path().string());
    std::sort(files.begin(), files.end());
  } else {
    files.push_back(path);
  }
  TrustedKeys trusted;
  trusted.source_ = path;
  for (const std::string& f : files) {
    refuseWritableByOthers(f);
    Bio bio(BIO_new_file(f.c_str(), "r"), &BIO_free);
    if (!bio) throw std::runtime_error(f + ": cannot open the trusted public key file");
    int in_file = 0;
    while (EVP_PKEY* raw = PEM_read_bio_PUBKEY(bio.get(), nullptr, nullptr, nullptr)) {
      PkeyPtr key(raw, &EVP_PKEY_free);
      if (!isEd25519(key.get())) throw std::runtime_error(f + ": a public key that is not Ed25519");
      trusted.keys_.push_back(rawPublicKey(key.get(), f));
      ++in_file;
    }
    ERR_clear_error();  // the read past the last key leaves an error on OpenSSL's queue
    if (in_file == 0) throw std::runtime_error(f + ": no PEM Ed25519 public key in it");
  }
  if (trusted.keys_.empty()) throw std::runtime_error(path + ": no trusted public key (*.pub) found");
  return trusted;
}

}  // namespace masa::integrity
