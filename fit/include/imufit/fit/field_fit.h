// imufit — the field fit: a calibration from a session by hand, without a table or a plan
// (`imufit fit --field`, docs/field.md). The model is the shared one (model/sensor_model.h,
// docs/spec.md section 1), its coefficients here constant in temperature (order 0; the parameter
// blocks hold kTerms terms per coefficient so that the cubic is a change of kTerms).
//
// The session: the unit rests in N >= 9 arbitrary poses and is turned by hand between them.
//
//  1. Poses. The rests are found on both sensors at once (run/segmentation.h's MotionDetector: a
//     noise floor from the whole log, gyro and accelerometer variance over a sliding window); a
//     steady piece of at least min_pose_s is a pose. Each pose is reduced to its raw means; the
//     white noise of a sample, per axis, is pooled over every pose (the noise floor of the log).
//  2. Turns. Between two successive poses the corrected gyro is integrated on the samples' own
//     time stamps (model/attitude_integration.h: quaternion, Runge-Kutta 4, rate linear between
//     samples), from the last sample of one pose to the first of the next.
//  3. The Ceres problem (fit/src/field_cost.h), every residual through the shared model's
//     CorrectWith(); the unknowns are the coefficients and, per pose, gravity's direction u_p
//     (two tangent parameters about its starting value):
//       accelerometer at pose p:  K_a (a_hat_p - g u_p) / sigma_a            3 residuals
//       gyro at pose p:           K_g omega_hat_p / sigma_g (at rest: zero)  3 residuals
//       turn from p to q:         E_q^T (R_pq^T u_p - u_q) / sigma_turn      2 residuals
//     with K = diag(S) inv(M) (errors in raw units, where the noise lives, as the table fit's
//     window_cost.h), sigma the noise of a pose's mean, R_pq the integrated turn, E_q two unit
//     vectors perpendicular to u_q, and sigma_turn the gyro's white noise integrated over the turn
//     (angle random walk). So |a_hat| = g fixes the accelerometer, the turns fix the gyro's scale
//     and misalignment, the static gyro means its bias and, through a_hat_p, its g-sensitivity H.
//     Earth's rotation (at most 7.3e-5 rad/s) is not modelled: the session has no north.
//  4. The body frame. Without a table it is a convention (docs/spec.md section 1, "field
//     calibration"): x along the accelerometer's x axis, y in the plane of its x and y axes, so the
//     accelerometer's misalignment xy, xz and yz are held at 0 (the body frame `accelerometer_xy`,
//     io/calibration.h).
//  5. Uncertainty. Every residual is normalised by its noise, so the covariance of the
//     coefficients is (J^T J)^-1 at the solution; `sigma` holds its square roots (0 for a held
//     term). Where a group of residuals (accelerometer at rest, gyro at rest, turns) is larger than
//     the white noise can explain (a real hand session: tremor, drift), its noise is scaled by its
//     variance-component estimate and the problem solved again, so that the sigmas stay honest. A session
//     that cannot determine a coefficient is refused, saying what it lacks in plain words (`undetermined`):
//     no pose near some direction, too few poses, turns too small about an axis, or a direction of the
//     problem with no information (named by the coefficient it moves most).
//
// Frames and units: raw inputs as the unit gives them; SI inside; the body frame above.
#ifndef IMUFIT_FIT_FIELD_FIT_H_
#define IMUFIT_FIT_FIELD_FIT_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "imufit/base/option_table.h"
#include "imufit/model/constants.h"
#include "imufit/model/sample.h"
#include "imufit/model/sensor_model.h"
#include "imufit/run/segmentation.h"

namespace imufit {

// The accelerometer's misalignment terms the convention holds at 0 (indices into its 6).
inline constexpr int kFieldHeldAccelMisalignment[3] = {0, 1, 3};  // xy, xz, yz

struct FieldFitOptions {
  // Local gravity, m/s^2: the length every pose's corrected specific force must have.
  double gravity_mps2 = kStandardGravityMps2;
  // Or local gravity from the site (model/local_gravity.h: WGS-84 normal gravity): geodetic
  // latitude, degrees, and height above the ellipsoid, m. Not together with gravity_mps2.
  std::optional<double> latitude_deg;
  double height_m = 0.0;
  // How rests are told from motion (window, noise quantile, threshold): the segmentation's.
  SegmentationOptions detection;
  // A steady stretch shorter than this is not a pose, s.
  double min_pose_s = 1.0;
  // Fewer poses than this is refused (9 accelerometer unknowns need 9 poses, and more are better).
  int min_poses = 9;
  // Whether the gyro g-sensitivity H is fitted (else held at 0).
  bool fit_g_sensitivity = true;
  // Over temperature (a warm-up, or several sessions at different temperatures): the order of the
  // polynomials in temperature of the biases (gyro and accelerometer) and of the scale factors
  // (gyro and accelerometer), 0..3. Misalignments and H stay constant. 0: one temperature.
  int bias_temp_order = 0;
  int scale_temp_order = 0;
  // A bias in temperature needs its poses to span this much, degC, and order + 1 of them at least
  // kDistinctTempC apart; a scale factor in temperature needs this span, and in the coldest and
  // warmest third of it a pose near each of the six directions and turns about each axis.
  double min_bias_temp_span_c = 2.0;
  double min_scale_temp_span_c = 10.0;
  // A pose is "near" a direction (+x, -x, ...) within this angle, degrees: every one of the six must
  // have one, or the accelerometer's scale and bias of that axis rest on one side only.
  double near_direction_deg = 50.0;
  // The turns must move gravity by at least this much about each gyro axis, rad (summed over the
  // turns: the rotation about the axis times the sine of gravity's angle to it).
  double min_turn_about_axis_rad = 0.5;
  // Refused beyond these 1-sigma: relative gyro and accelerometer scale, misalignment (rad).
  double max_relative_scale_sigma = 0.01;
  double max_misalignment_sigma_rad = 0.01;
  int max_iterations = 100;

  // An empty string when usable, else what is wrong.
  std::string Validate() const;
  // The gravity the fit uses: from latitude_deg and height_m when latitude_deg is set, else
  // gravity_mps2.
  double GravityMps2() const;
};

// Two poses' temperatures count as distinct when this far apart, degC.
inline constexpr double kDistinctTempC = 0.5;

// The options a user sets (gravity_mps2, min_pose_s), described once (base/option_table.h;
// field_fit_options.cc): `imufit fit --field` takes them from here.
const OptionTable<FieldFitOptions>& FieldFitOptionTable();

// A rest found in the session: its samples [first, last] (indices into the samples given) and means.
struct FieldPose {
  long long first = 0;
  long long last = 0;
  double start_s = 0.0;
  double end_s = 0.0;
  double temp_c = 0.0;                                   // mean reading
  Eigen::Vector3d gyro_mean = Eigen::Vector3d::Zero();   // raw
  Eigen::Vector3d accel_mean = Eigen::Vector3d::Zero();  // raw
  // After the fit: gravity's direction (up, body frame) and | |a_hat| - g |, m/s^2.
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  double accel_norm_error_mps2 = 0.0;
};

// The motion between two successive poses: the samples [first, last] integrated (the last of pose
// `from` to the first of pose `to`).
struct FieldTurn {
  int from = 0;
  int to = 0;
  long long first = 0;
  long long last = 0;
  // A gyro sample at a converter's limit (run/channel_check.h): the integrated rate is wrong, so the
  // turn is left out of the fit (its poses stay).
  bool saturated = false;
  double angle_rad = 0.0;  // after the fit: the angle gravity turned through
  // After the fit: the angle between gravity's direction at `to` and the one the turn predicts, rad.
  double direction_error_rad = 0.0;
};

enum class FieldFitStatus {
  kNotRun,
  kConverged,     // solved; the calibration is usable
  kUndetermined,  // the session does not determine the model; see `undetermined`
  kFailed,        // the solver did not converge; see `termination`
  kInconsistent,  // several sessions: one's biases disagree with the joint fit; see `sessions`
};

// Several sessions of one unit fitted jointly (FitFieldSessions): a session's biases against the
// joint fit. A MEMS unit's bias changes from one power-on to the next (turn-on repeatability); a
// joint fit of sessions recorded on separate power-ons would take that change for temperature. So
// every session is tested: were the session's bias (gyro, accelerometer: 3 raw offsets each) free of
// the joint curve, by how much would it move, with what covariance? That is the score (Lagrange
// multiplier) test of an offset of its own, from the joint fit's Jacobian J and residuals r (rows of
// other sessions zero in G, the bias columns of J restricted to the session's rows):
//   A = G^T (I - J (J^T J)^-1 J^T) G,  offset = -A^-1 G^T r,  covariance A^-1,
//   chi2 = offset^T A offset  (3 degrees of freedom when the session agrees).
// Where the joint curve absorbs a session's offset wholly (N sessions, each at one temperature,
// fitted with a bias of order N - 1), A vanishes and the session cannot be tested (`tested` false):
// the fit says so, because a turn-on offset is then taken for temperature unseen.
struct FieldSessionOffset {
  bool tested = false;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // raw units, as the model's bias
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();   // 1-sigma of each axis's offset
  double chi2 = 0.0;
  // Beyond chance (chi2 > kFieldSessionChi2: 1 in 10 000 for a session that agrees).
  bool beyond = false;
};
inline constexpr double kFieldSessionChi2 = 21.11;  // chi-square, 3 degrees of freedom, p = 1e-4

// What one session contributed to a fit (one session: all of it).
struct FieldSessionShare {
  std::string name;  // as the caller named it ("a.csv"), else "session N" (1-based)
  long long samples = 0;
  int first_pose = 0;  // its poses are summary.poses[first_pose, first_pose + poses)
  int poses = 0;
  int first_turn = 0;  // its turns are summary.turns[first_turn, first_turn + turns)
  int turns = 0;
  std::array<double, 2> temp_range_c{0.0, 0.0};                      // of its samples, degC
  Eigen::Vector3d gyro_noise_raw = Eigen::Vector3d::Constant(-1.0);  // its own noise floor
  Eigen::Vector3d accel_noise_raw = Eigen::Vector3d::Constant(-1.0);
  FieldSessionOffset gyro_bias;  // several sessions, after the fit
  FieldSessionOffset accel_bias;
};

struct FieldFitSummary {
  FieldFitStatus status = FieldFitStatus::kNotRun;
  // What the session cannot determine, in plain words ("no pose with gravity near -y (the y axis
  // up)", "turns about z too small to fix the gyro's z scale").
  std::vector<std::string> undetermined;
  std::vector<FieldPose> poses;
  std::vector<FieldTurn> turns;
  SensorModel model = SensorModel::Identity();  // basis: TemperatureBasis::Reference()
  SensorModel sigma{};                          // 1-sigma, same layout; 0 for a held term
  // 1-sigma of each coefficient's value at the coldest and the warmest pose (at order 0, sigma's
  // c0): what a user reads off the curve, which the terms' sigmas alone do not give.
  SensorModel sigma_at_low{};
  SensorModel sigma_at_high{};
  std::array<double, 2> temp_range_c{0.0, 0.0};       // of the samples, degC
  std::array<double, 2> pose_temp_range_c{0.0, 0.0};  // of the poses' mean readings, degC
  int iterations = -1;
  std::string termination;
  // Noise of one sample, raw, per axis (the log's floor, pooled over the poses).
  Eigen::Vector3d gyro_noise_raw = Eigen::Vector3d::Constant(-1.0);
  Eigen::Vector3d accel_noise_raw = Eigen::Vector3d::Constant(-1.0);
  // Residuals after the fit: | |a_hat| - g | over the poses (RMS, m/s^2), the corrected static gyro
  // (RMS over poses and axes, rad/s), gravity's direction after each turn fitted (RMS, rad), and
  // the reduced chi-square of the whole problem.
  double accel_norm_rms_mps2 = -1.0;
  double gyro_static_rms_radps = -1.0;
  double direction_rms_rad = -1.0;
  double reduced_chi2 = -1.0;
  // The noise of each residual group as a multiple of the log's white noise: the accelerometer at
  // rest, the gyro at rest, the turns. 1 unless the group's residuals exceed that noise beyond
  // chance (hand tremor, drift, correlated noise); then its variance-component estimate, by which
  // the group is weighted and its sigmas grow (field_fit.cc, NoiseScales()).
  std::array<double, 3> noise_scale{1.0, 1.0, 1.0};
  // The sessions fitted, in the order given (one for FitField). Pose and turn indices (FieldPose
  // first/last, FieldTurn from/to/first/last) count through the sessions one after the other: a
  // session's sample indices are offset by the samples of the sessions before it.
  std::vector<FieldSessionShare> sessions;

  bool IsSolutionUsable() const { return status == FieldFitStatus::kConverged; }
  // One line: the outcome, poses, turns and residuals.
  std::string BriefReport() const;
};

// Fits the model to a session by hand, `samples` in time order (raw; temp_c as read).
FieldFitSummary FitField(const std::vector<Sample>& samples, const FieldFitOptions& options);

// Several sessions of one unit (each in time order) fitted jointly (`imufit fit --field --samples A
// --samples B ...`, docs/field.md "Over temperature"): every session's rests are poses of one
// problem, turns join two successive rests of one session only (never the last of one session to
// the first of the next), each pose is weighted by its own session's noise floor, and the
// coefficients (with the temperature orders of `options`) are shared. The observability checks
// judge the poses and turns of all sessions together; a session without a pose at rest is
// refused by name. With two sessions or more, each session's biases are tested against the joint
// fit (FieldSessionOffset); one beyond chance makes the status kInconsistent (nothing to write:
// the sessions disagree, a turn-on offset or another unit), the coefficients still reported.
// `names` (empty, or one per session) name the sessions in the findings.
FieldFitSummary FitFieldSessions(const std::vector<std::vector<Sample>>& sessions,
                                 const FieldFitOptions& options, const std::vector<std::string>& names = {});

// Two sessions of one unit compared (`imufit fit --field --repeat`): for every coefficient both
// fitted, the difference of their values at 25 degC (c0) against the combined 1-sigma of two
// independent sessions, sqrt(sigma_a^2 + sigma_b^2). A hand procedure that is repeatable gives
// differences of about one combined sigma (z RMS near 1); a larger z names what the procedure does
// not reproduce (a pose held by hand that moved, a turn too fast for the gyro's range, ...).
struct FieldCoefficientDifference {
  bool gyro = true;
  int coefficient = 0;      // the model's index (model/sensor_model.h)
  double difference = 0.0;  // second - first, SI
  double combined_sigma = 0.0;
  double z = 0.0;  // difference / combined_sigma
};
struct FieldRepeatability {
  std::vector<FieldCoefficientDifference> differences;
  double z_rms = 0.0;
  // The threshold beyond which a difference is named (|z| > kFieldRepeatZ: by chance once in 370).
  static constexpr double kFieldRepeatZ = 3.0;
  std::vector<FieldCoefficientDifference> beyond;
};
FieldRepeatability CompareFieldFits(const FieldFitSummary& first, const FieldFitSummary& second);

// Step 1 alone: the poses and turns of a session (their means; `up` and the errors not set) and the
// noise floor. Poses the session lacks are reported by FitField, not here.
void FindFieldPoses(const std::vector<Sample>& samples, const FieldFitOptions& options,
                    std::vector<FieldPose>* poses, std::vector<FieldTurn>* turns,
                    Eigen::Vector3d* gyro_noise_raw, Eigen::Vector3d* accel_noise_raw);

}  // namespace imufit

#endif  // IMUFIT_FIT_FIELD_FIT_H_
