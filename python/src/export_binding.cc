// imufit Python module: imufit.export(), a calibration in a consumer's format as `imufit export`
// writes it (export/: the same ExportCalibration, options by the names of ExportOptionTable()).
#include <string>

#include "binding.h"
#include "imufit/export/export.h"
#include "imufit/io/calibration.h"
#include "imufit/io/output_file.h"
#include "imufit/io/sha256.h"
#include "keyword_options.h"

namespace imufit::python {
namespace {

// The worst case and RMS per axis (x, y, z) as arrays, deg/s and mg; None when nothing is lost.
py::object LossDict(const ExportLoss& loss) {
  if (!loss.measured) return py::none();
  const auto array = [](const Eigen::Vector3d& v) { return ToArray({v.x(), v.y(), v.z()}); };
  py::dict d;
  d["points"] = loss.points;
  d["gyro_worst_dps"] = array(loss.gyro_worst_dps);
  d["gyro_rms_dps"] = array(loss.gyro_rms_dps);
  d["accel_worst_mg"] = array(loss.accel_worst_mg);
  d["accel_rms_mg"] = array(loss.accel_rms_mg);
  return d;
}

// imufit.export(calibration, format, output=None, **options).
py::dict Export(const py::object& calibration, const std::string& format, const py::object& output,
                const py::kwargs& kwargs) {
  const std::string where = "imufit.export";
  ExportOptions options;
  py::dict keywords(kwargs);
  keywords["format"] = format;
  ApplyKeywords(ExportOptionTable(), where, keywords, &options);
  for (const auto& [key, value] : kwargs) {  // as the command: an option of other formats is refused
    const std::string name = py::str(key);
    if (!ExportOptionServes(name, options.format)) {
      ThrowBadArgument(
          where, name + ": only " + ExportOptionFormats(name) + " use it, not " + ToString(options.format));
    }
  }
  Calibration unit;
  if (py::isinstance<Calibration>(calibration)) {
    // Provenance of a calibration in memory: the SHA-256 of its YAML text, as it would be written.
    unit = calibration.cast<Calibration>();
    options.calibration_file = "(in memory)";
    options.calibration_sha256 = Sha256Hex(CalibrationToYaml(unit));
  } else {
    options.calibration_file = PathString(calibration);
    unit = ReadCalibration(options.calibration_file);
    options.calibration_sha256 = Sha256OfFile(options.calibration_file);
  }
  options.software = std::string("imufit ") + IMUFIT_VERSION + " (Python)";
  if (const std::string problem = options.Validate(); !problem.empty()) ThrowBadArgument(where, problem);
  std::string output_path;
  if (!output.is_none()) {
    output_path = PathString(output);
    if (!options.calibration_file.empty() && output_path == options.calibration_file)
      ThrowBadArgument(where, "output names the calibration file itself");
  }
  ExportResult result;
  {
    py::gil_scoped_release release;
    result = ExportCalibration(unit, options);
    if (!output_path.empty()) WriteFileAtomically(output_path, result.content);
  }
  py::dict d;
  d["content"] = py::bytes(result.content);
  d["loss"] = LossDict(result.loss);
  d["consumer"] = result.consumer;
  d["envelope"] = result.envelope;
  d["warnings"] = result.warnings;
  return d;
}

}  // namespace

void BindExport(py::module_& m) {
  m.def(
      "export", &Export, py::arg("calibration"), py::arg("format"), py::arg("output") = py::none(),
      "A calibration (a path or a Calibration) in a consumer's format, as `imufit export` writes it: "
      "{content: bytes, loss: {points, gyro_worst_dps, gyro_rms_dps, accel_worst_mg, accel_rms_mg} or None "
      "when nothing is lost, consumer, envelope, warnings: [str]}. Written to `output` (atomically) when "
      "given. "
      "Options by name: export_options(). Nothing is refused for its loss: compare `loss` with your bound.");
  m.def(
      "export_options", [] { return DescribeKeywords(ExportOptionTable()); },
      "{name: (default, description)} of the options imufit.export() takes by name (`imufit export`'s).");
}

}  // namespace imufit::python
