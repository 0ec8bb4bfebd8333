// imufit — the bytes of an input file, decompressed when it is gzip (io's own, not installed).
//
// A file is gzip when its name ends in ".gz" or when it starts with gzip's magic bytes 1f 8b (a
// compressed log someone named .csv is read as what it is, not as text). Decompression is ISA-L's
// igzip (streaming inflate, several times faster than zlib's), with the gzip wrapper read here: a
// stream cut short, a CRC-32 or length trailer that does not match, bytes after the last member, or
// a file named .gz that is not gzip are InputErrors. Concatenated members (`cat a.gz b.gz`) are
// one stream, as gzip(1) reads them. Every byte read from the file goes through the digest, when
// there is one, as it is read.
#ifndef IMUFIT_IO_SRC_BYTE_SOURCE_H_
#define IMUFIT_IO_SRC_BYTE_SOURCE_H_

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace imufit {

class Sha256;

class ByteSource {
 public:
  // Opens `path`; throws InputError. `digest` (may be null) must outlive the source.
  ByteSource(std::string path, Sha256* digest);
  ~ByteSource();
  ByteSource(const ByteSource&) = delete;
  ByteSource& operator=(const ByteSource&) = delete;

  // Reads up to `size` (decompressed) bytes; 0 at the end. Throws InputError.
  size_t Read(char* data, size_t size);
  bool gzip() const { return inflater_ != nullptr; }

 private:
  struct Inflater;
  size_t ReadRaw(char* data, size_t size);
  // Makes at least `need` unread raw bytes available (keeping those not yet used); false when the
  // file ends first.
  bool Fill(size_t need);
  void StartMember();
  void GiveBackUnusedBytes();
  void CheckTrailer();
  size_t Inflate(char* data, size_t size);
  [[noreturn]] void Truncated() const;

  std::string path_;
  Sha256* digest_;
  int fd_ = -1;
  std::vector<char> raw_;
  const char* in_ = nullptr;  // the unread raw bytes: [in_, in_ + in_left_)
  size_t in_left_ = 0;
  bool raw_eof_ = false;
  long long compressed_bytes_ = 0;  // raw bytes read from the file
  std::unique_ptr<Inflater> inflater_;
};

}  // namespace imufit

#endif  // IMUFIT_IO_SRC_BYTE_SOURCE_H_
