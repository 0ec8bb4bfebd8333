// --format json: the whole calibration in JSON for web and production-database consumers.
//
// The calibration file's own tree (docs/spec.md section 3: the coefficients, the sigma tree, the
// fit and noise blocks) written as JSON, so that ReadCalibration (a YAML 1.2 reader: JSON is YAML)
// reads it back bit for bit, with one key added: `export`, the provenance. Written by the one
// writer of machine-readable text (io/machine_text.h), from the same document as the YAML file:
// numbers as numbers in their shortest round-trip form, booleans as booleans; a non-finite figure
// of the fit or noise blocks (YAML's .nan, .inf) is written as null: JSON has no such numbers.
// Schema: docs/calibration.schema.json.
#include "export_internal.h"
#include "imufit/io/calibration.h"
#include "imufit/io/machine_text.h"

namespace imufit::export_internal {
namespace {

constexpr const char* kConsumer = "JSON (docs/calibration.schema.json)";

}  // namespace

ExportResult ExportJson(const Calibration& calibration, const ExportOptions& options) {
  ExportResult result;
  result.consumer = kConsumer;
  MachineDoc root = CalibrationDoc(calibration);
  root.Remove("export");  // a calibration read back from a JSON export: its provenance is replaced
  MachineDoc export_block = MachineDoc::Map();
  export_block.Add("software", MachineDoc::Text(options.software));
  export_block.Add("calibration_file", MachineDoc::Text(CalibrationFileName(options)));
  export_block.Add("calibration_sha256", MachineDoc::Text(options.calibration_sha256));
  export_block.Add("provenance", MachineDoc::Texts(ProvenanceLines(calibration, options, result),
                                                   MachineDoc::Style::kBlock));
  root.Add("export", std::move(export_block));
  result.content = JsonText(root);
  return result;
}

}  // namespace imufit::export_internal
