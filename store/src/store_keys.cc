// The content keys of the results store: UUIDv5 (RFC 9562, SHA-1 name-based) of what identifies a
// run and a fit, so the same run recorded twice, or at two stations, or merged twice is one row.
#include <openssl/sha.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <string>

#include "imufit/store/store.h"

namespace imufit {
namespace {

// imufit's UUID namespace (a fixed, random UUID: 6f1c2b1e-5d43-4c8a-9e0b-2a7d9c3f4e15).
constexpr std::array<unsigned char, 16> kNamespace = {0x6f, 0x1c, 0x2b, 0x1e, 0x5d, 0x43, 0x4c, 0x8a,
                                                      0x9e, 0x0b, 0x2a, 0x7d, 0x9c, 0x3f, 0x4e, 0x15};

std::string Uuid5(const std::string& name) {
  std::string input(kNamespace.begin(), kNamespace.end());
  input += name;
  unsigned char digest[SHA_DIGEST_LENGTH];
  SHA1(reinterpret_cast<const unsigned char*>(input.data()), input.size(), digest);
  digest[6] = static_cast<unsigned char>((digest[6] & 0x0f) | 0x50);  // version 5
  digest[8] = static_cast<unsigned char>((digest[8] & 0x3f) | 0x80);  // RFC variant
  std::string text;
  for (int i = 0; i < 16; ++i) {
    if (i == 4 || i == 6 || i == 8 || i == 10) text += '-';
    char hex[3];
    std::snprintf(hex, sizeof hex, "%02x", digest[i]);
    text += hex;
  }
  return text;
}

}  // namespace

std::string RunKey(const StoredFit& fit) {
  return Uuid5("run\n" + fit.serial + "\n" + fit.plan_sha256 + "\n" + fit.samples_sha256);
}

std::string FitKey(const StoredFit& fit) {
  return Uuid5("fit\n" + RunKey(fit) + "\n" + fit.time_utc + "\n" + fit.software + "\n" + fit.fit_options +
               "\n" + fit.limits_sha256 + "\n" + fit.status + "\n" + fit.verdict + "\n" + fit.message + "\n" +
               fit.calibration_yaml);
}

}  // namespace imufit
