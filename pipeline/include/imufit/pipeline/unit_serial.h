// imufit — which unit a run belongs to: its serial from the places that may name it, and what is
// said when they disagree (`imufit fit`, `report`, `batch`; docs/factory.md).
//
// A serial may be stated for this run by the operator (`--serial`, a batch unit's serial.txt),
// recorded in a calibration (`report`), written by the unit's logger into the samples header
// (`# serial:`), or given by the plan (`serial`, maybe a plan a whole lot shares). The first source
// in the caller's order that names a serial wins. Each other source that names a different one is
// a warning naming both sources and both serials: the certificate and stderr carry it.
//
// One disagreement is an error instead: a serial stated for this run that contradicts the samples
// file's own header. The operator typed or filed one unit's serial beside another unit's log (a
// factory mixing up files); certifying either unit from it would be wrong, so it is refused at the
// header's line unless the caller allows it (`--allow-mismatch`), and then it is a warning.
#ifndef IMUFIT_PIPELINE_UNIT_SERIAL_H_
#define IMUFIT_PIPELINE_UNIT_SERIAL_H_

#include <string>
#include <vector>

#include "imufit/io/samples.h"

namespace imufit {

struct SerialSource {
  enum class Kind {
    kStated,  // stated for this run: --serial, serial.txt
    kHeader,  // the samples file's own header
    kOther,   // a calibration, a plan
  };
  Kind kind = Kind::kOther;
  std::string name;    // how messages name the source: "--serial", "the plan plan.yaml", ...
  std::string serial;  // "" when this source names none
  // kHeader: where the serial is stated (file:line:column of the error).
  std::string file;
  long line = 0;
  long column = 0;
};

// The samples header's serial as a source (reads the file up to its header; throws InputError for a
// bad header, as ReadSamplesSerial does).
SerialSource SamplesHeaderSerial(const std::string& samples_path);
// The same from a reader of the file, which has read the header already.
SerialSource SamplesHeaderSerial(const SamplesReader& reader);
// The same of samples named `samples_name` whose header states `found`.
SerialSource SamplesHeaderSerial(const std::string& samples_name, const SamplesSerial& found);

struct UnitSerial {
  std::string serial;  // "" when no source names one
  std::vector<std::string> warnings;
};

// The serial of the first source that names one, and a warning for every source that names
// another. Throws InputError at the header's place when a kStated source contradicts a kHeader one,
// unless `allow_mismatch` (then that is a warning too, saying it was allowed).
UnitSerial ResolveSerial(const std::vector<SerialSource>& sources, bool allow_mismatch);

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_UNIT_SERIAL_H_
