// imufit — gzip compression of outputs (io's own, not installed): ISA-L's igzip, streaming deflate
// at its level 1, several times faster than zlib's default; the output is standard gzip (one
// member, with the CRC-32 and length trailer), read by gzip(1), zlib and Python.
//
// Compression and the writes to the file run on a thread of the writer's own, so that the caller's
// thread goes on making the next buffer meanwhile. At most kMaxPending buffers wait for it (memory
// stays bounded, and a caller faster than the compression waits); an error of the thread (a full
// disk) is thrown, with its message, by the caller's next Write() or by Finish().
#ifndef IMUFIT_IO_SRC_GZIP_WRITER_H_
#define IMUFIT_IO_SRC_GZIP_WRITER_H_

#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

namespace imufit {

// Writes all of `data` to `fd`; throws InputError naming `path` and the system's reason
// ("write failed: No space left on device").
void WriteAll(int fd, std::string_view data, const std::string& path);

class GzipWriter {
 public:
  // Compresses into `fd` (not owned); errors name `path`.
  GzipWriter(int fd, std::string path);
  // Stops the thread (what waits is not written: an output not finished is abandoned).
  ~GzipWriter();
  GzipWriter(const GzipWriter&) = delete;
  GzipWriter& operator=(const GzipWriter&) = delete;

  // Takes the bytes of `data` to compress, leaving `data` empty (a buffer compressed earlier, to
  // fill again). Throws the InputError of an earlier write.
  void Write(std::string* data);
  // Ends the stream (the last block and the trailer) and waits until all is written; throws the
  // InputError of any write. Call once; nothing may be written after.
  void Finish();

 private:
  struct Stream;
  static constexpr size_t kMaxPending = 2;
  // The thread: compresses the pending buffers in order, then the end of the stream.
  void Compress();
  void Deflate(std::string_view data);

  int fd_;
  std::string path_;
  std::unique_ptr<Stream> stream_;
  std::vector<unsigned char> out_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::string> pending_;  // to compress, in order
  std::vector<std::string> free_;    // compressed: their memory is reused
  bool finishing_ = false;           // Finish() was called: the stream ends after pending_
  bool done_ = false;                // the thread has ended (finished, or at an error)
  bool stop_ = false;                // the destructor's: end now
  std::exception_ptr error_;
  std::thread thread_;  // last: started when the rest is ready
};

}  // namespace imufit

#endif  // IMUFIT_IO_SRC_GZIP_WRITER_H_
