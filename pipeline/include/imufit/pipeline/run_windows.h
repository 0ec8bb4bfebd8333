// imufit — where files meet the fit: a run's samples file read into the fit's windows.
//
// imufit::pipeline links io (files) and fit (windows, the fit); the command, the benchmarks and
// any batch tooling build on it instead of re-writing the read loop.
//
// A run is read as few times as the work needs: once for a file with a segment column, twice for
// one without (the first pass finds the segments, segment_run.h). On the way the reader hashes the
// file (its SHA-256, for the calibration and the certificate) and, when asked, keeps the noise
// stretch (static_stretch.h, the certificate's noise), so that nobody reads it again.
#ifndef IMUFIT_PIPELINE_RUN_WINDOWS_H_
#define IMUFIT_PIPELINE_RUN_WINDOWS_H_

#include <optional>
#include <string>
#include <vector>

#include "imufit/io/memory_samples.h"
#include "imufit/io/plan.h"
#include "imufit/io/run_header.h"
#include "imufit/io/samples.h"
#include "imufit/io/sha256.h"
#include "imufit/pipeline/segment_run.h"
#include "imufit/pipeline/static_stretch.h"
#include "imufit/run/segmentation.h"
#include "imufit/run/windows.h"

namespace imufit {

struct RunWindows {
  std::vector<Window> windows;
  WindowStats stats;
  // Set when the file had no segment column and the segments were found in the data.
  std::optional<Segmentation> segmentation;
  // SHA-256 of the samples file's bytes as they are on disk, computed as they were read.
  std::string samples_sha256;
  // The run's noise stretch (static_stretch.h), when the reading was asked to keep it.
  std::optional<StaticStretch> static_stretch;
  // What the samples header says of the run (run_header.h; empty for a run held in memory).
  RunHeader header;
};

// A run's samples file, opened: its header is read (the serial in it can be checked before any
// work is done), then Read() reads the samples.
class RunReader {
 public:
  // Opens `samples_path` (CSV or .csv.gz) for a run of `plan` (which must outlive the reader), read
  // as `input` says. Throws InputError for a bad file or header.
  RunReader(const Plan& plan, std::string samples_path, const SamplesInput& input);
  // A run held in memory (which must outlive the reader), read as its file would be: the same
  // checks, windows and labelling; its hash is SamplesInMemory::Sha256().
  RunReader(const Plan& plan, const SamplesInMemory& samples, const SamplesInput& input);
  RunReader(const RunReader&) = delete;
  RunReader& operator=(const RunReader&) = delete;

  // The samples' name (the file's path) and the serial its header states.
  const std::string& name() const { return memory_ ? memory_->path() : first_pass_->path(); }
  const SamplesSerial& located_serial() const {
    return memory_ ? memory_->located_serial() : first_pass_->located_serial();
  }

  // What the samples header says of the run (acquired, model, firmware, ambient; run_header.h);
  // empty for a run held in memory. Throws InputError at a bad header line.
  RunHeader run_header() const {
    return memory_ ? RunHeader() : RunHeaderOf(first_pass_->path(), first_pass_->header_comments());
  }

  // Streams the samples through a WindowBuilder (once only). Throws InputError for bad input,
  // including a sample whose segment id the plan does not have (located at its line). A file
  // without a segment column is labelled first (one more pass over the file); then
  // PlanMismatchError says where the log and the plan disagree. With `noise_stretch`, keeps the
  // stretch it chooses (RunWindows::static_stretch; InputError when it names no static segment).
  RunWindows Read(const WindowOptions& options,
                  const std::optional<NoiseStretchOptions>& noise_stretch = std::nullopt);

 private:
  // The samples into `builder` (and `stretch` when not null): the run's segmentation and hash.
  RunWindows ReadFile(WindowBuilder* builder, NoiseStretchFinder* stretch);
  RunWindows ReadMemory(WindowBuilder* builder, NoiseStretchFinder* stretch);
  // Throws InputError when a run of `span_s` over `intervals` sample intervals is too short for
  // every segment of the plan to outlast the trim (SpanProblem: time in another unit?).
  void CheckSpan(const WindowOptions& options, double span_s, long long intervals) const;

  const Plan& plan_;
  SamplesInput input_;
  Sha256 digest_;
  std::optional<SamplesReader> first_pass_;  // a file: hashes into digest_
  std::optional<MemorySamplesReader> memory_;
  const SamplesInMemory* in_memory_ = nullptr;
  bool read_ = false;
};

// RunReader(plan, samples_path, input).Read(options).
RunWindows ReadRunWindows(const Plan& plan, const std::string& samples_path, const WindowOptions& options,
                          const SamplesInput& input = SamplesInput());

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_RUN_WINDOWS_H_
