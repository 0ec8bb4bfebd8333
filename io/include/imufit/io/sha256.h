// imufit — SHA-256 (FIPS 180-4), for the input hashes of certificates, batch manifests and the
// results store. Computed by libcrypto (OpenSSL's EVP interface, with the CPU's SHA instructions
// where it has them); tests/factory_test.cc checks it against the FIPS 180-2 vectors.
#ifndef IMUFIT_IO_SHA256_H_
#define IMUFIT_IO_SHA256_H_

#include <memory>
#include <string>
#include <string_view>

namespace imufit {

// Incremental SHA-256: Update() any number of times, then HexDigest() once. The state is kept
// out of this header, so that no user of it sees libcrypto. Readers hash a file while they
// stream it (csv_reader.h), so a file is read once for its samples and its hash.
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;

  void Update(std::string_view data);
  // The digest as 64 lowercase hex digits. Finishes the hash: call once.
  std::string HexDigest();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

std::string Sha256Hex(std::string_view data);
// The hash of a file's bytes as they are on disk (a .gz file is hashed compressed). Throws
// InputError naming the file when it cannot be read.
std::string Sha256OfFile(const std::string& path);

}  // namespace imufit

#endif  // IMUFIT_IO_SHA256_H_
