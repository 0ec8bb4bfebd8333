#include "imufit/io/sha256.h"

#include <fcntl.h>
#include <openssl/evp.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "imufit/io/error.h"
#include "imufit/model/check.h"

namespace imufit {

// libcrypto's SHA-256 (EVP), which uses the CPU's SHA instructions where it has them.
struct Sha256::State {
  EVP_MD_CTX* context = EVP_MD_CTX_new();
  ~State() { EVP_MD_CTX_free(context); }
};

Sha256::Sha256() : state_(std::make_unique<State>()) {
  IMUFIT_CHECK(state_->context != nullptr && EVP_DigestInit_ex(state_->context, EVP_sha256(), nullptr) == 1,
               "libcrypto cannot start a SHA-256");
}

Sha256::~Sha256() = default;

void Sha256::Update(std::string_view data) {
  IMUFIT_CHECK(EVP_DigestUpdate(state_->context, data.data(), data.size()) == 1,
               "libcrypto SHA-256 update failed");
}

std::string Sha256::HexDigest() {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int size = 0;
  IMUFIT_CHECK(EVP_DigestFinal_ex(state_->context, digest, &size) == 1 && size == 32,
               "libcrypto SHA-256 final failed");
  static const char* kHex = "0123456789abcdef";
  std::string hex;
  for (unsigned int i = 0; i < size; ++i) {
    hex += kHex[digest[i] >> 4];
    hex += kHex[digest[i] & 0xf];
  }
  return hex;
}

std::string Sha256Hex(std::string_view data) {
  Sha256 hash;
  hash.Update(data);
  return hash.HexDigest();
}

std::string Sha256OfFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
  Sha256 hash;
  char block[1 << 16];
  for (;;) {
    const ssize_t got = ::read(fd, block, sizeof block);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      ::close(fd);
      throw InputError(path, "read error");
    }
    if (got == 0) break;
    hash.Update(std::string_view(block, static_cast<size_t>(got)));
  }
  ::close(fd);
  return hash.HexDigest();
}

}  // namespace imufit
