// imufit Python module: the module itself, its exception types and the shared helpers.
#include <exception>

#include "binding.h"
#include "imufit/io/error.h"
#include "imufit/model/sensor_model.h"
#include "imufit/run/segmentation.h"

namespace imufit::python {

Exceptions& GetExceptions() {
  // Lives as long as the interpreter; never destroyed (no Python calls at static destruction).
  static Exceptions* exceptions = new Exceptions();
  return *exceptions;
}

namespace {

// Raises imufit.InputError with the location as attributes, from io's InputError.
void RaiseInputError(const std::string& what, const std::string& file, long line, long column,
                     const std::string& message) {
  const py::object& type = GetExceptions().input_error;
  py::object error = type(what);
  error.attr("file") = file;
  error.attr("line") = line;
  error.attr("column") = column;
  error.attr("message") = message;
  PyErr_SetObject(type.ptr(), error.ptr());
}

py::object NewExceptionType(py::module_& m, const char* name, PyObject* base, const char* doc) {
  const std::string qualified = std::string("imufit.") + name;
  py::object type =
      py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(qualified.c_str(), doc, base, nullptr));
  if (!type) throw py::error_already_set();
  m.attr(name) = type;
  return type;
}

}  // namespace

void ThrowBadArgument(const std::string& where, const std::string& message) {
  throw InputError(where, message);
}

std::string PathString(const py::handle& path) {
  return py::str(py::module_::import("os").attr("fspath")(path));
}

py::array_t<double> NewArray(py::ssize_t rows, py::ssize_t cols) {
  if (cols == 0) return py::array_t<double>(rows);
  return py::array_t<double>({rows, cols});
}

py::array_t<double> ToArray(const std::vector<double>& values) {
  py::array_t<double> array(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), array.mutable_data());
  return array;
}

py::dict CoefficientArrays(const double* params, int coefficients) {
  py::dict arrays;
  const auto group = [&](const char* name, int first, int count) {
    py::array_t<double> array = NewArray(count, kPolynomialTerms);
    std::copy(params + first * kPolynomialTerms, params + (first + count) * kPolynomialTerms,
              array.mutable_data());
    arrays[name] = array;
  };
  group("bias", kBiasCoefficient, 3);
  group("scale", kScaleCoefficient, 3);
  group("misalignment", kMisalignmentCoefficient, 6);
  if (coefficients == kGyroCoefficients) group("g_sensitivity", kGSensitivityCoefficient, 9);
  return arrays;
}

py::dict ModelArrays(const SensorModel& model) {
  py::dict arrays;
  arrays["gyro"] = CoefficientArrays(model.gyro.data(), kGyroCoefficients);
  arrays["accel"] = CoefficientArrays(model.accel.data(), kAccelCoefficients);
  return arrays;
}

}  // namespace imufit::python

PYBIND11_MODULE(_imufit, m) {
  namespace py = pybind11;
  using namespace imufit::python;
  m.doc() = "imufit: IMU thermal calibration (the C++ libraries of the imufit command)";
  m.attr("__version__") = IMUFIT_VERSION;

  Exceptions& exceptions = GetExceptions();
  exceptions.input_error = NewExceptionType(
      m, "InputError", PyExc_ValueError,
      "Bad input: a file, a value or an argument imufit cannot use. str() reads like a compiler "
      "diagnostic (file:line:column: message); the attributes file, line, column (0 = unknown) "
      "and message hold the parts.");
  exceptions.fit_error = NewExceptionType(m, "FitError", PyExc_RuntimeError,
                                          "The fit could not be done (the solver did not converge).");
  exceptions.undetermined_error = NewExceptionType(
      m, "UndeterminedError", exceptions.fit_error.ptr(),
      "The data do not determine the model. `missing` lists what is missing, one finding each, "
      "with what would determine it.");
  exceptions.plan_mismatch_error = NewExceptionType(
      m, "PlanMismatchError", exceptions.fit_error.ptr(),
      "A samples file without a segment column does not match its plan: the message says where the log "
      "and the plan disagree.");
  py::register_exception_translator([](std::exception_ptr pointer) {
    try {
      if (pointer) std::rethrow_exception(pointer);
    } catch (const imufit::InputError& error) {
      RaiseInputError(error.what(), error.file(), error.line(), error.column(), error.message());
    } catch (const imufit::PlanMismatchError& error) {
      PyErr_SetString(GetExceptions().plan_mismatch_error.ptr(), error.what());
    }
  });

  BindCalibration(m);
  BindFit(m);
  BindField(m);
  BindNoise(m);
  BindExport(m);
  BindPlan(m);
}
