// imufit Python module — what the binding files share.
//
// The module exposes the libraries as they are: io's calibration reader and writer, the shared
// model's correction (model/sensor_model.h), pipeline's FitRun, the simulator and noise/. This
// header holds the pieces every binding file needs: the exception types, the conversion of a
// path-like argument, and the construction of numpy arrays from C++ data.
//
// Errors, by who made the mistake (as the command's exit statuses):
//   imufit.InputError(ValueError)    bad input; carries file, line, column and message (io's
//                                    InputError, translated for every call)
//   imufit.FitError(RuntimeError)    the fit did not converge
//   imufit.UndeterminedError(FitError)  the data do not determine the model; `missing` lists
//                                    what is missing, one finding each
//   imufit.PlanMismatchError(FitError)  a log without a segment column does not match its plan
#ifndef IMUFIT_PYTHON_BINDING_H_
#define IMUFIT_PYTHON_BINDING_H_

#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "imufit/io/calibration.h"
#include "imufit/io/memory_samples.h"

namespace imufit::python {

namespace py = pybind11;

// A float64 array, C order, converted from whatever numpy array or sequence was given.
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// The exception types, created in module.cc.
struct Exceptions {
  py::object input_error;
  py::object fit_error;
  py::object undetermined_error;
  py::object plan_mismatch_error;
};
Exceptions& GetExceptions();

// Raises imufit.InputError(file, message): a bad argument, located at the function's name
// ("imufit.fit") the way the command locates a bad option at "imufit fit".
[[noreturn]] void ThrowBadArgument(const std::string& where, const std::string& message);

// Raises `type`(message) with the attributes given (an UndeterminedError's `missing`, ...).
[[noreturn]] void Raise(const py::object& type, const std::string& message, const py::dict& attributes);

// str(os.fspath(path)): a str or an os.PathLike.
std::string PathString(const py::handle& path);

// A new (rows, cols) or (rows,) float64 array; cols == 0 means one dimension.
py::array_t<double> NewArray(py::ssize_t rows, py::ssize_t cols = 0);
// A copy of `vectors` as an (N, 3) array.
py::array_t<double> Triads(const std::vector<Eigen::Vector3d>& vectors);
// A copy of `values` as a 1-D array.
py::array_t<double> ToArray(const std::vector<double>& values);

// The coefficients of one sensor as named arrays: {"bias": (3, 4), "scale": (3, 4),
// "misalignment": (6, 4), "g_sensitivity": (9, 4) (gyro only)}, rows in kCoefficientNames order,
// columns c0..c3 of powers of dT = T - reference_temp_c.
py::dict CoefficientArrays(const double* params, int coefficients);
// {"gyro": ..., "accel": ...} of CoefficientArrays.
py::dict ModelArrays(const SensorModel& model);

// The run of `samples` ({time_s, temp_c, gyro, accel; segment and serial optional}, as
// read_samples() and simulate() return it), its shapes checked; errors and its name say `where`,
// the public function called ("imufit.fit").
SamplesInMemory SamplesFromArrays(const py::dict& samples, const std::string& where);

void BindCalibration(py::module_& m);
void BindFit(py::module_& m);
void BindField(py::module_& m);
void BindNoise(py::module_& m);
void BindPlan(py::module_& m);
void BindExport(py::module_& m);

}  // namespace imufit::python

#endif  // IMUFIT_PYTHON_BINDING_H_
