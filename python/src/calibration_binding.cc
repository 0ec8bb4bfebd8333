// imufit Python module: Calibration (io's reader and writer, the shared model's correction and
// forward form, evaluation at temperatures, the fit's record) and samples files as numpy arrays.
#include <algorithm>
#include <cstdint>
#include <sstream>

#include "binding.h"
#include "imufit/io/calibration.h"
#include "imufit/io/samples.h"
#include "imufit/model/sensor_model.h"

namespace imufit::python {
namespace {

std::string ShapeText(const py::array& array) {
  std::ostringstream text;
  text << "(";
  for (py::ssize_t i = 0; i < array.ndim(); ++i) text << (i ? ", " : "") << array.shape(i);
  text << (array.ndim() == 1 ? ",)" : ")");
  return text.str();
}

// The number of 3-vectors in `array`: (N, 3) gives N, (3,) gives 1 with *single set.
py::ssize_t Triads(const std::string& where, const char* name, const py::array& array, bool* single) {
  *single = array.ndim() == 1 && array.shape(0) == 3;
  if (*single) return 1;
  if (array.ndim() != 2 || array.shape(1) != 3) {
    ThrowBadArgument(where, std::string(name) + " must have shape (N, 3) or (3,), not " + ShapeText(array));
  }
  return array.shape(0);
}

// Temperatures for n samples: a scalar (the same for all) or shape (n,). Returns the stride.
py::ssize_t TemperatureStride(const std::string& where, const py::array& temp_c, py::ssize_t n, bool single) {
  if (temp_c.ndim() == 0) return 0;
  if (temp_c.ndim() == 1 && temp_c.shape(0) == n && !single) return 1;
  ThrowBadArgument(
      where, "temp_c must be a number or have shape (" + std::to_string(n) + ",), not " + ShapeText(temp_c));
}

const SensorModel& SensorOf(const Calibration& calibration) { return calibration.model; }

// The parameter array of `sensor` ("gyro" or "accel") of `model`, and its coefficient count.
double* Parameters(SensorModel* model, const std::string& sensor, int* coefficients,
                   const std::string& where) {
  if (sensor == "gyro") {
    *coefficients = kGyroCoefficients;
    return model->gyro.data();
  }
  if (sensor == "accel") {
    *coefficients = kAccelCoefficients;
    return model->accel.data();
  }
  ThrowBadArgument(where,
                   "sensor " + py::repr(py::str(sensor)).cast<std::string>() + " is not one of: gyro, accel");
}

// Applies a (raw -> SI) or (SI -> raw) map of the model to every sample: the shared loop of
// correct() and forward(), with the GIL released.
template <typename Map>
py::tuple MapSamples(const std::string& where, const py::object& temp_c, const py::object& gyro,
                     const py::object& accel, const char* gyro_name, const char* accel_name, Map map) {
  const DoubleArray temps = DoubleArray::ensure(temp_c);
  const DoubleArray gyros = DoubleArray::ensure(gyro);
  const DoubleArray accels = DoubleArray::ensure(accel);
  if (!temps || !gyros || !accels) {
    throw py::error_already_set();
  }
  bool single = false;
  bool accel_single = false;
  const py::ssize_t n = Triads(where, gyro_name, gyros, &single);
  if (Triads(where, accel_name, accels, &accel_single) != n || accel_single != single) {
    ThrowBadArgument(where, std::string(accel_name) + " has shape " + ShapeText(accels) + " but " +
                                gyro_name + " has " + ShapeText(gyros));
  }
  const py::ssize_t temp_stride = TemperatureStride(where, temps, n, single);
  py::array_t<double> gyro_out = single ? NewArray(3) : NewArray(n, 3);
  py::array_t<double> accel_out = single ? NewArray(3) : NewArray(n, 3);
  const double* t = temps.data();
  const double* g = gyros.data();
  const double* a = accels.data();
  double* g_out = gyro_out.mutable_data();
  double* a_out = accel_out.mutable_data();
  {
    py::gil_scoped_release release;
    Eigen::Vector3d gyro_result;
    Eigen::Vector3d accel_result;
    for (py::ssize_t i = 0; i < n; ++i) {
      map(t[i * temp_stride], Eigen::Vector3d(g[3 * i], g[3 * i + 1], g[3 * i + 2]),
          Eigen::Vector3d(a[3 * i], a[3 * i + 1], a[3 * i + 2]), &gyro_result, &accel_result);
      std::copy(gyro_result.data(), gyro_result.data() + 3, g_out + 3 * i);
      std::copy(accel_result.data(), accel_result.data() + 3, a_out + 3 * i);
    }
  }
  return py::make_tuple(gyro_out, accel_out);
}

// The coefficients of both sensors at each temperature (CoefficientsAt of the shared model).
py::dict Evaluate(const Calibration& calibration, const py::object& temp_c) {
  const DoubleArray temps = DoubleArray::ensure(temp_c);
  if (!temps) throw py::error_already_set();
  const bool scalar = temps.ndim() == 0;
  if (!scalar && temps.ndim() != 1) {
    ThrowBadArgument("imufit.Calibration.evaluate",
                     "temp_c must be a number or have shape (N,), not " + ShapeText(temps));
  }
  const py::ssize_t n = scalar ? 1 : temps.shape(0);
  const SensorModel& model = SensorOf(calibration);
  py::dict result;
  for (const bool gyro : {true, false}) {
    const auto vectors = [&] { return scalar ? NewArray(3) : NewArray(n, 3); };
    const auto matrices = [&] {
      return scalar ? py::array_t<double>({py::ssize_t{3}, py::ssize_t{3}})
                    : py::array_t<double>({n, py::ssize_t{3}, py::ssize_t{3}});
    };
    py::array_t<double> bias = vectors(), scale = vectors(), misalignment = matrices(),
                        g_sensitivity = matrices();
    for (py::ssize_t i = 0; i < n; ++i) {
      const double x = model.basis.Argument(temps.data()[i]);
      const SensorCoefficients<double> c = gyro ? CoefficientsAt(model.gyro.data(), kGyroCoefficients, x)
                                                : CoefficientsAt(model.accel.data(), kAccelCoefficients, x);
      for (int r = 0; r < 3; ++r) {
        bias.mutable_data()[3 * i + r] = c.bias(r);
        scale.mutable_data()[3 * i + r] = c.scale(r);
        for (int k = 0; k < 3; ++k) {
          misalignment.mutable_data()[9 * i + 3 * r + k] = c.misalignment(r, k);
          g_sensitivity.mutable_data()[9 * i + 3 * r + k] = c.g_sensitivity(r, k);
        }
      }
    }
    py::dict sensor;
    sensor["bias"] = bias;
    sensor["scale"] = scale;
    sensor["misalignment"] = misalignment;
    if (gyro) sensor["g_sensitivity"] = g_sensitivity;
    result[gyro ? "gyro" : "accel"] = sensor;
  }
  return result;
}

// Sets the coefficients of `group` of `sensor` from an array of shape (count, 4).
void SetCoefficients(SensorModel* model, const std::string& sensor, const std::string& group,
                     const py::object& values) {
  const std::string where = "imufit.Calibration.set_coefficients";
  int coefficients = 0;
  double* params = Parameters(model, sensor, &coefficients, where);
  int first = -1;
  int count = 0;
  if (group == "bias") first = kBiasCoefficient, count = 3;
  if (group == "scale") first = kScaleCoefficient, count = 3;
  if (group == "misalignment") first = kMisalignmentCoefficient, count = 6;
  if (group == "g_sensitivity" && coefficients == kGyroCoefficients)
    first = kGSensitivityCoefficient, count = 9;
  if (first < 0) {
    ThrowBadArgument(where, "group \"" + group + "\" is not one of: bias, scale, misalignment" +
                                (coefficients == kGyroCoefficients ? ", g_sensitivity" : " (accel)"));
  }
  const DoubleArray array = DoubleArray::ensure(values);
  if (!array) throw py::error_already_set();
  if (array.ndim() != 2 || array.shape(0) != count || array.shape(1) != kPolynomialTerms) {
    ThrowBadArgument(where, sensor + " " + group + " must have shape (" + std::to_string(count) +
                                ", 4), not " + ShapeText(array));
  }
  std::copy(array.data(), array.data() + count * kPolynomialTerms, params + first * kPolynomialTerms);
}

py::dict ReadSamples(const py::object& path) {
  SamplesReader reader(PathString(path), /*require_segment=*/false);
  std::vector<double> time_s, temp_c, gyro, accel;
  std::vector<int64_t> segment;
  Sample sample;
  {
    py::gil_scoped_release release;
    while (reader.Next(&sample)) {
      time_s.push_back(sample.time_s);
      temp_c.push_back(sample.temp_c);
      segment.push_back(sample.segment);
      gyro.insert(gyro.end(), sample.gyro.data(), sample.gyro.data() + 3);
      accel.insert(accel.end(), sample.accel.data(), sample.accel.data() + 3);
    }
  }
  const py::ssize_t n = static_cast<py::ssize_t>(time_s.size());
  py::dict samples;
  samples["time_s"] = ToArray(time_s);
  samples["temp_c"] = ToArray(temp_c);
  if (reader.has_segment()) {
    py::array_t<int64_t> segments(n);
    std::copy(segment.begin(), segment.end(), segments.mutable_data());
    samples["segment"] = segments;
  }
  py::array_t<double> gyros = NewArray(n, 3), accels = NewArray(n, 3);
  std::copy(gyro.begin(), gyro.end(), gyros.mutable_data());
  std::copy(accel.begin(), accel.end(), accels.mutable_data());
  samples["gyro"] = gyros;
  samples["accel"] = accels;
  if (!reader.serial().empty()) samples["serial"] = reader.serial();
  return samples;
}

}  // namespace

SamplesInMemory SamplesFromArrays(const py::dict& samples, const std::string& where) {
  const auto column = [&](const char* name) {
    if (!samples.contains(name)) ThrowBadArgument(where, std::string("samples has no \"") + name + "\"");
    DoubleArray array = DoubleArray::ensure(samples[name]);
    if (!array) throw py::error_already_set();
    return array;
  };
  const DoubleArray time_s = column("time_s"), temp_c = column("temp_c"), gyro = column("gyro"),
                    accel = column("accel");
  const py::ssize_t n = time_s.ndim() == 1 ? time_s.shape(0) : -1;
  const auto check = [&](const char* name, const py::array& array, int cols) {
    const bool ok = cols == 0 ? array.ndim() == 1 && array.shape(0) == n
                              : array.ndim() == 2 && array.shape(0) == n && array.shape(1) == cols;
    if (!ok) {
      ThrowBadArgument(where, std::string(name) + " has shape " + ShapeText(array) + "; expected (" +
                                  std::to_string(n) + (cols ? ", 3)" : ",)"));
    }
  };
  if (n < 0) ThrowBadArgument(where, "time_s must have shape (N,), not " + ShapeText(time_s));
  check("temp_c", temp_c, 0);
  check("gyro", gyro, 3);
  check("accel", accel, 3);
  SamplesInMemory run;
  run.name = where + " samples";
  run.has_segment = samples.contains("segment");
  py::array_t<int64_t, py::array::c_style | py::array::forcecast> segment;
  if (run.has_segment) {
    segment = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(samples["segment"]);
    if (!segment) throw py::error_already_set();
    check("segment", segment, 0);
  }
  if (samples.contains("serial") && !samples["serial"].is_none()) {
    run.serial.serial = py::str(samples["serial"]);
    SerialComment(run.serial.serial, where);  // refuses a control character
  }
  run.samples.resize(static_cast<size_t>(n));
  for (py::ssize_t i = 0; i < n; ++i) {
    Sample& sample = run.samples[static_cast<size_t>(i)];
    sample.time_s = time_s.data()[i];
    sample.temp_c = temp_c.data()[i];
    sample.segment = run.has_segment ? static_cast<int>(segment.data()[i]) : kTransitionSegment;
    sample.gyro = Eigen::Vector3d(gyro.data() + 3 * i);
    sample.accel = Eigen::Vector3d(accel.data() + 3 * i);
  }
  return run;
}

namespace {

void WriteSamples(const py::object& path, const py::dict& samples, const std::string& comment) {
  const SamplesInMemory run = SamplesFromArrays(samples, "imufit.write_samples");
  std::string header = SerialComment(run.serial.serial, "imufit.write_samples");
  if (!comment.empty()) header += (header.empty() ? "" : "\n") + comment;
  SamplesWriter writer(PathString(path), run.has_segment, header);
  for (const Sample& sample : run.samples) writer.Write(sample);
  writer.Commit();
}

// ---------------------------------------------------------------- the bindings, by part

// The fit's record (io/fit_record.h): one read-only attribute per key of its table, None when the
// file does not say.
void BindFitRecords(py::module_& m) {
#define IMUFIT_RECORD_ATTRIBUTE(type, key, description) .def_readonly(#key, &Record::key, description)
  {
    using Record = FieldRecord;
    py::class_<Record>(m, "FieldRecord",
                       "A calibration by hand (`imufit fit --field`): the session's own figures, the `fit: "
                       "field:` block.") IMUFIT_FIELD_RECORD_FIELDS(IMUFIT_RECORD_ATTRIBUTE);
  }
  {
    using Record = FitRecord;
    py::class_<Record>(m, "FitRecord",
                       "What the fit did and on which files: the calibration's `fit:` block, each key an "
                       "attribute (None when the file does not say).")
        IMUFIT_FIT_RECORD_FIELDS(IMUFIT_RECORD_ATTRIBUTE);
  }
  {
    using Record = CheckRecord;
    py::class_<Record>(m, "CheckRecord",
                       "The calibration's errors on a held-out run (`imufit fit --check-samples`): its "
                       "`check:` block.") IMUFIT_CHECK_RECORD_FIELDS(IMUFIT_RECORD_ATTRIBUTE);
  }
#undef IMUFIT_RECORD_ATTRIBUTE
}

// The file: reading, writing, and what it says besides the coefficients.
void BindCalibrationFile(py::class_<Calibration>& c) {
  c.def(py::init([] {
          Calibration calibration;
          calibration.model = SensorModel::Identity();
          return calibration;
        }),
        "The identity calibration: unit scale factors, no bias, misalignment or g-sensitivity.")
      .def_static(
          "load", [](const py::object& path) { return ReadCalibration(PathString(path)); }, py::arg("path"),
          "Reads a calibration YAML file; raises InputError (file:line:column) on bad input.")
      .def(
          "save", [](const Calibration& c, const py::object& path) { WriteCalibration(PathString(path), c); },
          py::arg("path"), "Writes the calibration YAML atomically; write -> load gives the same doubles.")
      .def("to_yaml", &CalibrationToYaml, "The calibration file's text.")
      .def_readwrite("serial", &Calibration::serial)
      .def_readwrite("created_utc", &Calibration::created_utc)
      .def_readwrite("software", &Calibration::software)
      .def_readwrite(
          "body_frame", &Calibration::body_frame,
          "The body frame's convention of a calibration by hand ('accelerometer_xy'), or None: the "
          "axes of the table's fixture.")
      .def_property(
          "fit_temp_range_c",
          [](const Calibration& c) { return py::make_tuple(c.fit_temp_range_c[0], c.fit_temp_range_c[1]); },
          [](Calibration& c, std::array<double, 2> range) { c.fit_temp_range_c = range; },
          "(min, max) of the temperatures the fit saw, degC.")
      .def_property_readonly(
          "reference_temp_c", [](const Calibration& c) { return c.model.basis.center_c; },
          "The temperature at which dT = 0, degC (25 in files imufit writes).")
      .def_readonly("fit", &Calibration::fit,
                    "What the fit did and on which files (FitRecord), or None when the file does not say.")
      .def_readonly("check", &Calibration::check,
                    "The errors on a held-out run (CheckRecord), or None when the fit had none.");
}

// The coefficients: named arrays, the flat parameter layout, their values at temperatures.
void BindCoefficients(py::class_<Calibration>& c) {
  c.def_property_readonly(
       "gyro", [](const Calibration& c) { return CoefficientArrays(c.model.gyro.data(), kGyroCoefficients); },
       "Gyro coefficients (copies): {bias: (3, 4) raw, scale: (3, 4) raw per rad/s, misalignment: (6, 4), "
       "g_sensitivity: (9, 4) raw per m/s^2}; columns c0..c3 of powers of dT.")
      .def_property_readonly(
          "accel",
          [](const Calibration& c) { return CoefficientArrays(c.model.accel.data(), kAccelCoefficients); },
          "Accelerometer coefficients (copies): {bias: (3, 4) raw, scale: (3, 4) raw per m/s^2, "
          "misalignment: (6, 4)}.")
      .def_property_readonly(
          "sigma",
          [](const Calibration& c) -> py::object {
            if (!c.sigma) return py::none();
            return ModelArrays(*c.sigma);
          },
          "1-sigma of every coefficient as {gyro: {...}, accel: {...}} in the layout of `gyro` and "
          "`accel`, or None when the file has none.")
      .def(
          "parameters",
          [](Calibration& c, const std::string& sensor) {
            int coefficients = 0;
            const double* params =
                Parameters(&c.model, sensor, &coefficients, "imufit.Calibration.parameters");
            return ToArray(std::vector<double>(params, params + coefficients * kPolynomialTerms));
          },
          py::arg("sensor"),
          "The flat parameter array of 'gyro' (84) or 'accel' (48): coefficient i, term k at i * 4 + k, in "
          "the order of COEFFICIENT_NAMES.")
      .def(
          "set_coefficients",
          [](Calibration& c, const std::string& sensor, const std::string& group, const py::object& values) {
            SetCoefficients(&c.model, sensor, group, values);
          },
          py::arg("sensor"), py::arg("group"), py::arg("values"),
          "Sets one group ('bias', 'scale', 'misalignment', 'g_sensitivity') of 'gyro' or 'accel' from an "
          "array of shape (count, 4).")
      .def("evaluate", &Evaluate, py::arg("temp_c"),
           "The coefficients at temperatures temp_c (degC; a number or shape (N,)): {gyro: {bias (N, 3) raw, "
           "scale (N, 3), misalignment (N, 3, 3), g_sensitivity (N, 3, 3)}, accel: {...}}.");
}

// A method of Calibration that maps arrays of samples through the model's `map` (Correct or
// Forward), the argument names its own.
using ModelMap = void (SensorModel::*)(double, const Eigen::Vector3d&, const Eigen::Vector3d&,
                                       Eigen::Vector3d*, Eigen::Vector3d*) const;
auto SampleMethod(const char* where, const char* gyro_name, const char* accel_name, ModelMap map) {
  return
      [=](const Calibration& c, const py::object& temp_c, const py::object& gyro, const py::object& accel) {
        const SensorModel& model = c.model;
        return MapSamples(where, temp_c, gyro, accel, gyro_name, accel_name,
                          [&model, map](double t, const Eigen::Vector3d& g, const Eigen::Vector3d& a,
                                        Eigen::Vector3d* g_out,
                                        Eigen::Vector3d* a_out) { (model.*map)(t, g, a, g_out, a_out); });
      };
}

// The shared model's correction and its inverse on arrays of samples.
void BindCorrection(py::class_<Calibration>& c) {
  c.def("correct", SampleMethod("imufit.Calibration.correct", "gyro_raw", "accel_raw", &SensorModel::Correct),
        py::arg("temp_c"), py::arg("gyro_raw"), py::arg("accel_raw"),
        "Corrects raw samples: (omega_hat_radps, a_hat_mps2), each (N, 3), bit for bit what `imufit apply` "
        "writes. temp_c degC, shape (N,) or a number; gyro_raw, accel_raw raw, shape (N, 3) (or (3,)).")
      .def("forward",
           SampleMethod("imufit.Calibration.forward", "omega_true_radps", "a_true_mps2",
                        &SensorModel::Forward),
           py::arg("temp_c"), py::arg("omega_true_radps"), py::arg("a_true_mps2"),
           "The raw outputs (gyro_raw, accel_raw) of a unit with this calibration for true rates (rad/s) and "
           "specific forces (m/s^2): the exact inverse of correct().")
      .def("__repr__", [](const Calibration& c) {
        return "<imufit.Calibration serial=" + py::repr(py::str(c.serial)).cast<std::string>() +
               " fit_temp_range_c=(" + FormatDouble(c.fit_temp_range_c[0]) + ", " +
               FormatDouble(c.fit_temp_range_c[1]) + ")" + (c.sigma ? " with sigma" : "") + ">";
      });
}

// The coefficient names and the samples files as arrays.
void BindSamplesFiles(py::module_& m) {
  py::list names;
  for (const CoefficientName& name : kCoefficientNames) {
    names.append(std::string(name.group) + "." + name.axis);
  }
  m.attr("COEFFICIENT_NAMES") = names;

  m.def("read_samples", &ReadSamples, py::arg("path"),
        "Reads a samples file (CSV or .csv.gz) into {time_s (N,), temp_c (N,), segment (N,) int64 when the "
        "file has it, gyro (N, 3), accel (N, 3)}; raises InputError on bad input.");
  m.def("write_samples", &WriteSamples, py::arg("path"), py::arg("samples"), py::arg("comment") = "",
        "Writes samples ({time_s, temp_c, [segment], gyro, accel}) atomically in the samples layout, every "
        "number in its shortest round-trip form.");
}

}  // namespace

void BindCalibration(py::module_& m) {
  BindFitRecords(m);
  py::class_<Calibration> calibration(
      m, "Calibration",
      "A calibration (calibration.yaml): the coefficients of the shared model, each a cubic "
      "in dT = T - reference_temp_c, with their 1-sigma when the fit wrote them.");
  BindCalibrationFile(calibration);
  BindCoefficients(calibration);
  BindCorrection(calibration);
  BindSamplesFiles(m);
}

}  // namespace imufit::python
