// imufit — gzip compression of outputs (io's own, not installed): ISA-L's igzip, streaming deflate
// at its level 1, several times faster than zlib's default; the output is standard gzip (one
// member, with the CRC-32 and length trailer), read by gzip(1), zlib and Python.
#ifndef IMUFIT_IO_SRC_GZIP_WRITER_H_
#define IMUFIT_IO_SRC_GZIP_WRITER_H_

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace imufit {

// Writes all of `data` to `fd`; throws InputError naming `path` and the system's reason
// ("write failed: No space left on device").
void WriteAll(int fd, std::string_view data, const std::string& path);

class GzipWriter {
 public:
  // Compresses into `fd` (not owned); errors name `path`.
  GzipWriter(int fd, std::string path);
  ~GzipWriter();
  GzipWriter(const GzipWriter&) = delete;
  GzipWriter& operator=(const GzipWriter&) = delete;

  void Write(std::string_view data);
  // Ends the stream (the last block and the trailer). Call once; nothing may be written after.
  void Finish();

 private:
  struct Stream;
  void Deflate(std::string_view data);

  int fd_;
  std::string path_;
  std::unique_ptr<Stream> stream_;
  std::vector<unsigned char> out_;
};

}  // namespace imufit

#endif  // IMUFIT_IO_SRC_GZIP_WRITER_H_
