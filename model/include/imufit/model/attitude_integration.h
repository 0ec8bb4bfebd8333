// imufit — the attitude integrated from angular rate samples on their own time stamps: what the
// field fit (fit/field_fit.h) compares with the change of gravity's direction across a turn.
//
// q is the unit quaternion (w, x, y, z) of R(t), which maps body-frame vectors at time t into the
// body frame at the start (R(0) = I), and obeys
//
//   dq/dt = 1/2 q (x) (0, omega(t)),      omega in rad/s, body frame at time t.
//
// Between two samples (t0, omega0) and (t1, omega1) the rate is taken as linear in time (the
// samples' own interval h = t1 - t0, however irregular: a lost sample is a longer step) and the
// equation is integrated with the classical 4th-order Runge-Kutta step, then renormalised. The
// error of the interpolation integrates to dt^2/12 (omega'(end) - omega'(start)) per axis, zero for
// a turn that starts and ends at rest, and the coning error of a rotating axis is of 4th order in h.
//
// Function templates over the scalar T, as the correction model (sensor_model.h): the fit runs them
// with ceres::Jet, tests with double. Nothing here can fail.
#ifndef IMUFIT_MODEL_ATTITUDE_INTEGRATION_H_
#define IMUFIT_MODEL_ATTITUDE_INTEGRATION_H_

#include <Eigen/Core>

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

// One Runge-Kutta step of h seconds from q, the rate going linearly from omega0 to omega1.
template <typename T>
Quaternion4<T> IntegrateAttitudeStep(const Quaternion4<T>& q, const Vector3<T>& omega0,
                                     const Vector3<T>& omega1, const T& h) {
  const Vector3<T> omega_mid = T(0.5) * (omega0 + omega1);
  const T half = T(0.5) * h;
  const Quaternion4<T> k1 = QuaternionRate(q, omega0);
  const Quaternion4<T> k2 = QuaternionRate((q + half * k1).eval(), omega_mid);
  const Quaternion4<T> k3 = QuaternionRate((q + half * k2).eval(), omega_mid);
  const Quaternion4<T> k4 = QuaternionRate((q + h * k3).eval(), omega1);
  const Quaternion4<T> next = q + (h / T(6.0)) * (k1 + T(2.0) * k2 + T(2.0) * k3 + k4);
  return next / next.norm();
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
