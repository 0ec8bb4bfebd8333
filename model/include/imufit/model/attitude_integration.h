// imufit — the attitude integrated from angular rate samples on their own time stamps: what the
// field fit (fit/field_fit.h) compares with the change of gravity's direction across a turn.
//
// q is the unit quaternion (w, x, y, z) of R(t), which maps body-frame vectors at time t into the
// body frame at the start (R(0) = I), and obeys
//
//   dq/dt = 1/2 q (x) (0, omega(t)),      omega in rad/s, body frame at time t.
//
// Between two samples (t0, omega0) and (t1, omega1), the samples' own interval h = t1 - t0 however
// irregular (a lost sample is a longer step), the equation is integrated with the classical
// 4th-order Runge-Kutta step, then renormalised. RK4 needs the rate at the step's middle too: the
// cubic through the two samples either side (Lagrange, on their actual times), or the mean of the
// two at the ends of a series. With the rate taken linear instead, the error of the interpolation
// turns with the body and leaves an error of order h^2 whenever the rotation axis moves (about
// 4e-5 rad per hand turn at 100 Hz); with the cubic it is of order h^4.
//
// Function templates over the scalar T, as the correction model (sensor_model.h): the fit runs them
// with ceres::Jet, tests with double. Nothing here can fail.
#ifndef IMUFIT_MODEL_ATTITUDE_INTEGRATION_H_
#define IMUFIT_MODEL_ATTITUDE_INTEGRATION_H_

#include <array>
#include <cstddef>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross

#include "imufit/model/sensor_model.h"

namespace imufit {

template <typename T>
using Quaternion4 = Eigen::Matrix<T, 4, 1>;  // (w, x, y, z)

// 1/2 q (x) (0, omega): the derivative of q.
template <typename T>
Quaternion4<T> QuaternionRate(const Quaternion4<T>& q, const Vector3<T>& omega) {
  Quaternion4<T> dq;
  dq(0) = T(-0.5) * (q(1) * omega(0) + q(2) * omega(1) + q(3) * omega(2));
  dq(1) = T(0.5) * (q(0) * omega(0) + q(2) * omega(2) - q(3) * omega(1));
  dq(2) = T(0.5) * (q(0) * omega(1) + q(3) * omega(0) - q(1) * omega(2));
  dq(3) = T(0.5) * (q(0) * omega(2) + q(1) * omega(1) - q(2) * omega(0));
  return dq;
}

// One Runge-Kutta step of h seconds from q, the rate omega0 at its start, omega_mid at its middle
// and omega1 at its end.
template <typename T>
Quaternion4<T> IntegrateAttitudeStep(const Quaternion4<T>& q, const Vector3<T>& omega0,
                                     const Vector3<T>& omega_mid, const Vector3<T>& omega1, const T& h) {
  const T half = T(0.5) * h;
  const Quaternion4<T> k1 = QuaternionRate(q, omega0);
  const Quaternion4<T> k2 = QuaternionRate((q + half * k1).eval(), omega_mid);
  const Quaternion4<T> k3 = QuaternionRate((q + half * k2).eval(), omega_mid);
  const Quaternion4<T> k4 = QuaternionRate((q + h * k3).eval(), omega1);
  const Quaternion4<T> next = q + (h / T(6.0)) * (k1 + T(2.0) * k2 + T(2.0) * k3 + k4);
  return next / next.norm();
}

// The weights of the rates at times t[0..3] whose sum is the cubic through them at the middle of
// t[1]..t[2] (Lagrange). Times in s, strictly increasing.
inline std::array<double, 4> MidpointWeights(const double* t) {
  const double middle = 0.5 * (t[1] + t[2]);
  std::array<double, 4> w;
  for (int i = 0; i < 4; ++i) {
    w[i] = 1.0;
    for (int j = 0; j < 4; ++j) {
      if (j != i) w[i] *= (middle - t[j]) / (t[i] - t[j]);
    }
  }
  return w;
}

// The attitude after `count` rate samples omega[k] at times_s[k] (the first at the start): the
// steps above, the rate at each step's middle from the cubic through its neighbours where the series
// has them.
template <typename T>
Quaternion4<T> IntegrateAttitude(const double* times_s, const Vector3<T>* omega, size_t count) {
  Quaternion4<T> q(T(1.0), T(0.0), T(0.0), T(0.0));
  for (size_t k = 1; k < count; ++k) {
    Vector3<T> omega_mid = T(0.5) * (omega[k - 1] + omega[k]);
    if (k >= 2 && k + 1 < count) {
      const std::array<double, 4> w = MidpointWeights(times_s + k - 2);
      omega_mid =
          T(w[0]) * omega[k - 2] + T(w[1]) * omega[k - 1] + T(w[2]) * omega[k] + T(w[3]) * omega[k + 1];
    }
    q = IntegrateAttitudeStep(q, omega[k - 1], omega_mid, omega[k], T(times_s[k] - times_s[k - 1]));
  }
  return q;
}

// R(q)^T v: a vector given in the body frame at the start, seen in the body frame at time t (a
// world-fixed direction such as gravity's, when the start frame is held still).
template <typename T>
Vector3<T> RotateIntoCurrentFrame(const Quaternion4<T>& q, const Vector3<T>& v) {
  const T& w = q(0);
  const Vector3<T> u(q(1), q(2), q(3));
  // R^T v = v + 2 w (v x u) + 2 u x (u x v), the rotation by the conjugate quaternion.
  const Vector3<T> uv = u.cross(v);
  return v - T(2.0) * w * uv + T(2.0) * u.cross(uv);
}

}  // namespace imufit

#endif  // IMUFIT_MODEL_ATTITUDE_INTEGRATION_H_
