"""Type stub of imufit: IMU thermal calibration (the C++ libraries of the imufit command).

Units: SI unless a name says otherwise. Raw outputs ("raw") are the unit's own numbers
(counts, nominal deg/s, ...). Corrected gyro rates are rad/s, specific forces m/s^2, both in the
body frame. Temperatures are degC. Coefficients are cubics in dT = T - reference_temp_c (25 degC),
columns c0..c3 of powers of dT. See docs/python.md and docs/conventions.md.
"""

import dataclasses
import os
from collections.abc import Mapping, Sequence
from typing import Any, TypedDict, Unpack, overload

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
PathLike = str | os.PathLike[str]

COEFFICIENT_NAMES: list[str]
"""The 21 gyro coefficients in parameter order, "group.axis" ("bias.x" .. "g_sensitivity.zz");
the accelerometer uses the first 12."""

class InputError(ValueError):
    """Bad input (a file, a value or an argument). str(): "file:line:column: message"."""

    file: str
    line: int  # 1-based; 0 = unknown
    column: int  # 1-based (CSV: field number); 0 = unknown
    message: str  # without the location

class FitError(RuntimeError):
    """The fit could not be done (the solver did not converge)."""

    diagnostics: dict[str, Any]

class UndeterminedError(FitError):
    """The data do not determine the model."""

    missing: list[str]  # one finding each, with what would determine it

class PlanMismatchError(FitError):
    """A samples file without a segment column does not match its plan (the message says where)."""

class FieldRecord:
    """A calibration by hand (`imufit fit --field`): the session's own figures, the `fit: field:`
    block. Read-only; SI units as the names say."""

    poses: int | None  # rests the fit used
    turns: int | None  # turns between them the fit used
    gravity_mps2: float | None  # the local gravity the fit used, m/s^2
    accel_norm_rms_mps2: float | None  # RMS over the rests of |a| - g after correction, m/s^2
    gyro_static_rms_radps: float | None  # RMS of the corrected gyro at rest, over rests and axes, rad/s
    gravity_direction_rms_rad: float | None  # RMS over the turns of the gravity direction's error, rad
    reduced_chi2: float | None  # reduced chi-square of the weighted residuals
    noise_scale_accel_rests: float | None  # the rests' accelerometer noise as a multiple of the log's white noise
    noise_scale_gyro_rests: float | None  # the rests' gyro noise as a multiple of the log's white noise
    noise_scale_turns: float | None  # the turns' noise as a multiple of the log's white noise
    saturated_turns: int | None  # turns left out because a gyro axis touched its converter's rail
    gravity_source: str | None  # stated, latitude or standard: where gravity_mps2 came from
    latitude_deg: float | None  # with gravity_source latitude: the geodetic latitude, degrees
    height_m: float | None  # with gravity_source latitude: the height above the ellipsoid, m
    session_samples: list[str] | None  # several sessions fitted jointly: the samples files, as given, in order (one session: absent)
    session_samples_sha256: list[str] | None  # SHA-256 of each session's samples file
    session_samples_read: list[int] | None  # samples in each session's file
    session_poses: list[int] | None  # rests each session contributed
    session_turns: list[int] | None  # turns within each session (none joins two sessions)
    session_temp_min_c: list[float] | None  # each session's coldest reading, degC
    session_temp_max_c: list[float] | None  # each session's warmest reading, degC
    session_biases_tested: bool | None  # whether each session's biases could be tested against the joint fit (false: the curve in temperature absorbs a session's offset, a turn-on offset is taken for temperature unseen)
    session_gyro_bias_chi2: list[float] | None  # when tested: each session's gyro bias offset from the joint fit, chi-square for 3
    session_accel_bias_chi2: list[float] | None  # when tested: each session's accelerometer bias offset from the joint fit, chi-square for 3

class FitRecord:
    """What the fit did and on which files: the calibration's `fit:` block, each key an attribute
    (None when the file does not say). Read-only; SI units as the names say."""

    plan: str | None  # the plan file, as given
    samples: str | None  # the samples file, as given
    plan_sha256: str | None  # SHA-256 of the plan file
    samples_sha256: str | None  # SHA-256 of the samples file
    acquired_utc: str | None  # when the run was recorded (the samples header's '# acquired:'), UTC
    unit_model: str | None  # the product's model or part number (the samples header's '# model:')
    unit_firmware: str | None  # the unit's firmware (the samples header's '# firmware:')
    ambient: str | None  # the laboratory's conditions (the samples header's '# ambient:')
    samples_read: int | None  # samples in the file
    segments_found_in_data: int | None  # a file without a segment column: the segments found in the data
    plan_passes_found: int | None  # a file without a segment column: complete passes through the plan
    windows_used: int | None  # windows the fit used
    windows_downweighted: int | None  # windows the robust loss down-weighted
    distinct_temperatures_c: list[float] | None  # the distinct temperatures of the windows, degC
    iterations: int | None  # solver iterations over all passes
    termination: str | None  # why the solver stopped, in its own words
    gyro_residual_rms_radps: float | None  # RMS of the gyro residuals, rad/s
    accel_residual_rms_mps2: float | None  # RMS of the accelerometer residuals, m/s^2
    gyro_reduced_chi2: float | None  # reduced chi-square of the gyro residuals
    accel_reduced_chi2: float | None  # reduced chi-square of the accelerometer residuals
    gyro_temp_order: int | None  # order of the gyro's temperature polynomials
    accel_temp_order: int | None  # order of the accelerometer's temperature polynomials
    g_sensitivity_fitted: bool | None  # whether the gyro g-sensitivity was fitted (else held at zero)
    fitted: list[str] | None  # the coefficient groups the fit estimated, e.g. gyro.bias
    held: list[str] | None  # the groups held at their stated values (sigma 0)
    held_values: str | None  # where the held values came from: prior, or scale 1, others 0
    uncalibrated_sensors: list[str] | None  # sensors held whole without a prior (gyro, accel): not calibrated by this file
    loss: str | None  # the robust loss
    gyro_bias_stability_radps: float | None  # the gyro bias stability in the sigmas, rad/s (0: white noise)
    accel_bias_stability_mps2: float | None  # the accelerometer bias stability in the sigmas, m/s^2
    bias_correlation_s: float | None  # correlation time of that bias wander, s
    segments_without_windows: list[int] | None  # plan segments without a single usable window
    missing_segments: int | None  # how many segments that is
    inconsistent: str | None  # written with --write-inconsistent: why the fit is inconsistent
    field: FieldRecord | None  # a calibration by hand (fit --field): the session's own figures

class CheckRecord:
    """The errors on a held-out run (`imufit fit --check-samples`): the `check:` block."""

    samples: str | None  # the held-out samples file, as given
    gyro_error_rms_radps: float | None  # RMS of the gyro errors over it, rad/s
    accel_error_rms_mps2: float | None  # RMS of the accelerometer errors, m/s^2

class Calibration:
    """A calibration (calibration.yaml): the shared model's coefficients and their 1-sigma."""

    serial: str
    created_utc: str  # ISO 8601 UTC
    software: str
    fit_temp_range_c: tuple[float, float]  # degC, the temperatures the fit saw
    body_frame: str | None  # a calibration by hand: its body frame's convention ('accelerometer_xy'); None: the fixture's axes

    def __init__(self) -> None:
        """The identity calibration: unit scale, no bias, misalignment or g-sensitivity."""
    @staticmethod
    def load(path: PathLike) -> Calibration:
        """Reads a calibration YAML; raises InputError (file:line:column) on bad input."""
    def save(self, path: PathLike) -> None:
        """Writes the calibration YAML atomically; save -> load gives the same doubles."""
    def to_yaml(self) -> str: ...
    @property
    def reference_temp_c(self) -> float:
        """Temperature at which dT = 0, degC (25 in files imufit writes)."""
    @property
    def gyro(self) -> dict[str, FloatArray]:
        """Copies: bias (3, 4) raw; scale (3, 4) raw per rad/s; misalignment (6, 4) rows xy xz yx yz
        zx zy, 1; g_sensitivity (9, 4) rows xx..zz, raw per m/s^2. Columns c0..c3 (per degC^k)."""
    @property
    def accel(self) -> dict[str, FloatArray]:
        """Copies: bias (3, 4) raw; scale (3, 4) raw per m/s^2; misalignment (6, 4)."""
    @property
    def sigma(self) -> dict[str, dict[str, FloatArray]] | None:
        """1-sigma of every coefficient, {"gyro": ..., "accel": ...} as above; None if the file has none."""
    @property
    def fit(self) -> FitRecord | None:
        """What the fit did and on which files; None if the file has no `fit:` block."""
    @property
    def check(self) -> CheckRecord | None:
        """The errors on a held-out run; None if the fit had none."""
    def parameters(self, sensor: str) -> FloatArray:
        """Flat parameters of "gyro" (84,) or "accel" (48,): coefficient i, term k at 4 i + k."""
    def set_coefficients(self, sensor: str, group: str, values: ArrayLike) -> None:
        """Sets group "bias" | "scale" | "misalignment" | "g_sensitivity" of "gyro" | "accel" from (count, 4)."""
    def evaluate(self, temp_c: ArrayLike) -> dict[str, dict[str, FloatArray]]:
        """Coefficients at temp_c (degC, a number or (N,)): {"gyro": {bias (N, 3) raw, scale (N, 3),
        misalignment (N, 3, 3), g_sensitivity (N, 3, 3)}, "accel": {bias, scale, misalignment}}."""
    def correct(self, temp_c: ArrayLike, gyro_raw: ArrayLike, accel_raw: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """(omega_hat_radps, a_hat_mps2), each (N, 3): bit for bit what `imufit apply` writes.
        temp_c degC (N,) or a number; gyro_raw, accel_raw raw (N, 3) or (3,). Releases the GIL."""
    def forward(self, temp_c: ArrayLike, omega_true_radps: ArrayLike, a_true_mps2: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """(gyro_raw, accel_raw) a unit with this calibration outputs for the truth: inverse of correct()."""

def read_samples(path: PathLike) -> dict[str, FloatArray | IntArray]:
    """A samples file (CSV or .csv.gz) as {time_s (N,) s, temp_c (N,) degC, segment (N,) int64 if
    present, gyro (N, 3), accel (N, 3), serial (str) if its header states one}. Raises InputError on
    bad input."""

def write_samples(path: PathLike, samples: Mapping[str, ArrayLike], comment: str = "") -> None:
    """Writes {time_s, temp_c, [segment], gyro, accel, [serial]} atomically, shortest round-trip
    numbers (the serial as a `# serial:` line)."""

@dataclasses.dataclass
class FitResult:
    calibration: Calibration
    sigma: dict[str, dict[str, FloatArray]]  # 1-sigma, layout of Calibration.gyro / .accel
    diagnostics: dict[str, Any]
    """termination, iterations, initial_cost, final_cost, windows_used, windows_downweighted,
    distinct_temperatures_c (degC), temp_range_c, gyro_residual_rms_radps, accel_residual_rms_mps2,
    gyro_reduced_chi2, accel_reduced_chi2, samples_read, transition_samples, trimmed_samples,
    short_windows, lost_samples, gaps, longest_gap_s (s), off_grid_samples, turns_dropped_for_gaps,
    turns_off_grid, time_stamp_note (what the time stamps showed, as `imufit fit` prints it),
    saturated_windows, saturation_note,
    brief_report, full_report, windows {segment, occurrence, samples, start_s,
    end_s, temp_c, gyro_mean, accel_mean, gyro_std, accel_std}, residuals {window, gyro_radps,
    accel_mps2, gyro_sigma_radps, accel_sigma_mps2, downweighted}, folds {temp_c, fitted, why_not,
    gyro_temp_order, accel_temp_order, order_lowered, errors {segment, windows, accel_windows (those
    with a known specific force, over which the accel figures are), gyro_rms_radps, ...}},
    check_errors."""

class _FitOptions(TypedDict, total=False):
    """The keyword options of fit(): the keys of fit_options(), SI (tests/test_options.py checks
    that the two agree). Defaults and descriptions: fit_options()."""

    fit: str  # "all" | "gyro" | "gyro-bias" | "accel" | "accel-bias", comma-separated; the rest held
    prior: PathLike  # calibration YAML whose values the held groups keep
    gyro_temp_order: int  # 0..3
    accel_temp_order: int  # 0..3
    fit_g_sensitivity: bool
    loss: str  # "none" | "huber" | "cauchy"
    loss_scale: float
    gyro_bias_stability_radps: float  # rad/s
    accel_bias_stability_mps2: float  # m/s^2
    bias_correlation_s: float  # s
    max_iterations: int
    closed_form_start: bool
    threads: int
    distinct_temp_c: float  # degC
    min_excitation_rate_radps: float  # rad/s
    rank_tolerance: float
    trim_s: float  # s
    window_temp_span_c: float  # degC
    window_max_duration_s: float  # s
    window_min_samples: int
    max_turn_gap_s: float  # s
    gyro_full_scale_raw: float  # raw
    accel_full_scale_raw: float  # raw
    temp_c: float | None  # degC, for a run without a temp_c column
    time_unit: str  # the unit of the time_s column: "s" (default), "ms", "us" or "ns"
    delimiter: str  # what separates a file's fields: "," (default), ";" or "tab"
    decimal_comma: bool  # a file's numbers are written 1,5 (with delimiter ";" or "tab")
    column: str  # columns a file names its own way: "time_s=Time,temp_c=T"
    segment_window_s: float  # s; this and the next six: finding the segments of a run without a segment column
    segment_noise_quantile: float
    segment_threshold_factor: float
    min_steady_s: float  # s
    direction_tolerance_deg: float  # deg
    rate_tolerance: float
    turn_margin_s: float  # s
    validate: bool
    check_samples: PathLike
    check_plan: PathLike
    write_inconsistent: bool
    noise_segment: str  # a static plan segment's id: the certificate's noise stretch (default: nearest 25 degC)
    allow_serial_mismatch: bool

def fit(plan: PathLike | Mapping[str, Any], samples: PathLike | Mapping[str, Any], **options: Unpack[_FitOptions]) -> FitResult:
    """Fits the thermal model to a run, as `imufit fit` does. plan: plan YAML path or the plan as a
    dict; samples: a path or arrays as simulate() and read_samples() return (with "serial"), fitted
    in memory (no file written). Options: _FitOptions (SI; defaults and descriptions from
    fit_options()). Raises InputError, UndeterminedError (what is missing), PlanMismatchError,
    FitError (not converged)."""

def fit_options() -> dict[str, tuple[Any, str]]:
    """{name: (default, description)} of every option of fit()."""

@dataclasses.dataclass
class FieldFitResult:
    calibration: Calibration  # body_frame "accelerometer_xy"; fit.field holds the session's figures
    sigma: dict[str, dict[str, FloatArray]]  # 1-sigma, layout of Calibration.gyro / .accel
    summary: dict[str, Any]
    """status, brief_report (the line `imufit fit --field` prints), undetermined (what the session
    lacks, in words), samples_read, serial, iterations, termination, temp_range_c,
    pose_temp_range_c, gyro_noise_raw, accel_noise_raw (one sample's noise per axis, raw),
    accel_norm_rms_mps2, gyro_static_rms_radps, direction_rms_rad, reduced_chi2, noise_scale
    (accel at rest, gyro at rest, turns), poses {first, last, start_s, end_s, temp_c, gyro_mean,
    accel_mean (raw), up (body frame), accel_norm_error_mps2}, turns {from, to, saturated,
    angle_rad, direction_error_rad}."""

class _FieldFitOptions(TypedDict, total=False):
    """The keyword options of fit_field(): the keys of fit_field_options(), SI (tests/test_options.py
    checks that the two agree)."""

    gravity_mps2: float  # m/s^2, local gravity
    latitude_deg: float | None  # deg: local gravity from the site instead (WGS-84 normal gravity)
    height_m: float  # m, with latitude_deg: above the WGS-84 ellipsoid
    min_pose_s: float  # s
    bias_temp_order: int  # 0..3
    scale_temp_order: int  # 0..3
    fit_g_sensitivity: bool
    temp_c: float | None  # degC, for a log without a temp_c column
    time_unit: str
    delimiter: str
    decimal_comma: bool
    column: str
    segment_window_s: float  # s; this and the next three: telling rests from motion
    segment_noise_quantile: float
    segment_threshold_factor: float
    min_steady_s: float  # s
    allow_serial_mismatch: bool

def fit_field(samples: PathLike | Mapping[str, Any], **options: Unpack[_FieldFitOptions]) -> FieldFitResult:
    """Fits a session by hand, as `imufit fit --field` does: samples a path or arrays as
    read_samples() returns. Raises InputError (a table fit's option too), UndeterminedError (what the
    session lacks, in the command's words), FitError."""

def fit_field_options() -> dict[str, tuple[Any, str]]:
    """{name: (default, description)} of every option of fit_field()."""

class _SimulateOptions(TypedDict, total=False):
    """The keyword options of simulate(): the keys of simulate_options() (tests/test_options.py
    checks that the two agree). Defaults and descriptions: simulate_options()."""

    soak_temps_c: Sequence[float]  # degC: one pass through the plan at each
    ramp_c: tuple[float, float] | None  # (from, to) degC across `passes` passes; None: soaks
    passes: int
    dwell_s: float  # s
    transition_s: float  # s
    rate_hz: float  # Hz
    start_time_s: float  # s
    gyro_noise_density: float  # rad/s/sqrt(Hz)
    accel_noise_density: float  # m/s^2/sqrt(Hz)
    gyro_random_walk: float  # rad/s^2/sqrt(Hz)
    accel_random_walk: float  # m/s^3/sqrt(Hz)
    gyro_bias_instability: float  # rad/s
    accel_bias_instability: float  # m/s^2
    bias_correlation_s: float  # s
    temp_noise_c: float  # degC
    quantize: bool
    time_jitter_s: float  # s
    drop_probability: float  # lost samples: the arrays are then shorter
    drop_burst: int
    gyro_full_scale_raw: float  # outputs clipped
    accel_full_scale_raw: float
    seed: int

def simulate(
    plan: PathLike, truth: Calibration | PathLike, **options: Unpack[_SimulateOptions]
) -> dict[str, FloatArray | IntArray]:
    """The run `imufit simulate` writes, sample for sample: {time_s, temp_c, segment, gyro, accel
    (raw), omega_true_radps (rad/s), a_true_mps2 (m/s^2)}. Options: _SimulateOptions (defaults and
    descriptions from simulate_options())."""

def simulate_options() -> dict[str, tuple[Any, str]]:
    """{name: (default, description)} of every option of simulate()."""

class _PlanCheckOptions(TypedDict, total=False):
    """plan_check()'s own keywords: the keys of plan_check_options() (tests/test_plan.py checks that
    the two agree). The schedule and the noise are simulate()'s keywords; noise_yaml a path."""

    tolerance: str | Mapping[str, float]  # {"gyro.bias": 0.01} or "gyro.bias=0.01,accel.bias=0.5"
    z: float
    spec_range_c: tuple[float, float] | None  # degC
    latitude_deg: float | None  # deg; None: the plan's
    weak_tolerance: float
    cut_loss: float
    min_ratio: float  # with limits: tolerance / U at least this (4: 4:1)
    trim_s: float  # s; the fit's window options: the windows the fit will cut
    window_temp_span_c: float  # degC
    window_max_duration_s: float  # s
    window_min_samples: int
    max_turn_gap_s: float  # s
    gyro_full_scale_raw: float  # a nominal unit never clips: no effect
    accel_full_scale_raw: float

class _PlanDesignOptions(_PlanCheckOptions, total=False):
    """plan_design()'s own keywords: the keys of plan_design_options()."""

    positions: str  # "faces,edges,corners"
    rates_dps: Sequence[float]  # deg/s, each as a +- pair
    max_rate_dps: float  # deg/s
    two_axis: bool
    set_points_c: Sequence[float]  # degC
    soak_settle_s: float  # s
    prior: str | Mapping[str, float]  # data-sheet 1-sigma per group
    max_exchange_rounds: int
    gravity_mps2: float | None  # m/s^2, the station's, written into the plan

class _PlanRows(TypedDict):
    name: list[str]  # "gyro bias x (linear term)", the limiting one first
    unit: list[str]
    sigma: npt.NDArray[np.float64]
    sigma_range: npt.NDArray[np.float64]
    sigma_spec: npt.NDArray[np.float64]
    tolerance: npt.NDArray[np.float64]  # 0: none
    ratio: npt.NDArray[np.float64]  # z sigma / tolerance; 0: none
    white_share: npt.NDArray[np.float64]

class PlanCheckResult(TypedDict):
    undetermined: list[str]
    weak: list[str]
    rows: _PlanRows
    limiting: str | None
    segments: dict[str, npt.NDArray[np.float64]]  # id, limiting_loss, worst_loss (inf: essential)
    correlated: list[tuple[str, str, float]]
    carriers: list[int]
    cuttable: list[int]
    plan_hours: float
    needed_hours: float
    plan_range_c: tuple[float, float]
    best_soaks_c: npt.NDArray[np.float64]
    temperature_efficiency: float
    extrapolation_factor: float
    tolerance_unmet: bool
    warnings: list[str]

class PlanDesignResult(TypedDict):
    undetermined: list[str]
    met: bool
    soaks_c: npt.NDArray[np.float64]
    hours: float
    greedy_soaks_c: npt.NDArray[np.float64]
    greedy_hours: float
    plan_yaml: str
    segment_count: int
    check: PlanCheckResult
    greedy_check: PlanCheckResult

def plan_check(plan: PathLike | Mapping[str, Any], **options: Any) -> PlanCheckResult:
    """What `imufit plan check` prints, as arrays (docs/plan.md). Keywords: _PlanCheckOptions, the
    schedule and noise of simulate() (_SimulateOptions), noise_yaml. Raises InputError."""

def plan_check_options() -> dict[str, tuple[Any, str]]:
    """{name: (default, description)} of plan_check()'s own keywords."""

def plan_design(candidates: PathLike | Mapping[str, Any] | None = None, **options: Any) -> PlanDesignResult:
    """What `imufit plan design` finds, as arrays (docs/plan.md). Keywords: _PlanDesignOptions, the
    schedule and noise of simulate(), noise_yaml. Raises InputError."""

def plan_design_options() -> dict[str, tuple[Any, str]]:
    """{name: (default, description)} of plan_design()'s own keywords."""

class AllanResult:
    """An Allan-family deviation at several taus with confidence intervals (NIST SP 1065)."""

    @property
    def estimator(self) -> str: ...
    @property
    def tau0_s(self) -> float: ...
    @property
    def n_samples(self) -> int: ...
    @property
    def mean(self) -> float:
        """Mean of y removed before the analysis, units of y."""
    @property
    def m(self) -> IntArray:
        """Averaging factors tau / tau0."""
    @property
    def tau_s(self) -> FloatArray:
        """Averaging times, s."""
    @property
    def terms(self) -> IntArray:
        """Number of terms of the estimator at each tau."""
    @property
    def dev(self) -> FloatArray:
        """Deviation, units of y (tdev: units of y times s)."""
    @property
    def dev_lo(self) -> FloatArray:
        """Lower bound of the confidence interval (nan: no edf)."""
    @property
    def dev_hi(self) -> FloatArray:
        """Upper bound of the confidence interval (nan: no edf)."""
    @property
    def edf(self) -> FloatArray: ...
    @property
    def alpha(self) -> IntArray: ...
    def __len__(self) -> int: ...

def allan(
    y: ArrayLike,
    tau0_s: float,
    estimator: str = ...,
    taus: str | Sequence[float] = "octave",
    confidence: float = ...,
    edf_noise: str = ...,
    threads: int = ...,
) -> AllanResult:
    """Allan deviation (adev, oadev, mdev, tdev, hdev, ohdev, totdev) of rates y (N,) (e.g. rad/s)
    sampled every tau0_s s, at taus "octave" | "decade" | "all" | "per-decade:K" | taus in s.
    Same numbers as `imufit allan` for one column. The defaults of estimator, confidence (one
    sigma), edf_noise and threads: allan_options() (tests/test_options.py checks the keywords)."""

def allan_options() -> dict[str, tuple[Any, str]]:
    """{name: (default, description)} of allan()'s options from the library's option table."""

def export(
    calibration: str | os.PathLike[str] | Calibration,
    format: str,
    output: str | os.PathLike[str] | None = None,
    **options: Any,
) -> dict[str, Any]:
    """The calibration in a consumer's format, as `imufit export` writes it (docs/export.md):
    {content: bytes, loss: {points, gyro_worst_dps, gyro_rms_dps, accel_worst_mg, accel_rms_mg}
    (arrays x, y, z; deg/s and mg) or None for a lossless format, consumer, envelope, warnings: a list
    of sentences, one per thing the user must know}.
    Written atomically to `output` when given. Options: export_options(). Nothing is refused for
    its loss: compare `loss` with your bound. Raises InputError for a bad option or calibration."""

def export_options() -> dict[str, tuple[Any, str]]:
    """{name: (default, description)} of export()'s options (`imufit export`'s option table)."""

class NoiseTerms:
    """IEEE 952 model sigma^2 = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2,
    SI units of y (gyro in rad/s: Q rad, N rad/sqrt(s), B rad/s, K rad/s/sqrt(s), R rad/s^2)."""

    @property
    def fitted(self) -> bool: ...
    @property
    def message(self) -> str: ...
    @property
    def points_used(self) -> int: ...
    @property
    def reduced_chi_square(self) -> float: ...
    @property
    def value(self) -> dict[str, float]:
        """quantization, random_walk, bias_instability, rate_random_walk, rate_ramp."""
    @property
    def sigma(self) -> dict[str, float]:
        """1-sigma of each value."""
    @property
    def variance(self) -> dict[str, float]: ...
    @property
    def variance_sigma(self) -> dict[str, float]: ...
    @property
    def free(self) -> dict[str, bool]: ...
    @property
    def arw(self) -> float:
        """N, rad/sqrt(s) for a gyro (x 180/pi x 60 = deg/sqrt(h)); m/s/sqrt(s) for an accelerometer."""
    @property
    def arw_sigma(self) -> float: ...
    @property
    def bias_instability(self) -> float:
        """B, rad/s for a gyro (x 180/pi x 3600 = deg/h)."""
    @property
    def bias_instability_sigma(self) -> float: ...
    @property
    def rrw(self) -> float:
        """K, rad/s/sqrt(s) for a gyro (x 180/pi x 3600 x 60 = deg/h/sqrt(h))."""
    @property
    def rrw_sigma(self) -> float: ...
    @property
    def readouts(self) -> dict[str, Any]:
        """IEEE 952 read-outs from the curve: random_walk (along the -1/2 segment, random_walk_sigma,
        random_walk_taus_s), bias_instability (minimum / 0.664, bias_tau_s, bias_interval at 95 %,
        bias_resolved), rate_random_walk (along the +1/2 segment, its sigma and taus), skipped_tau_s;
        nan where the curve has no such region."""
    @property
    def describes_curve(self) -> bool:
        """False when the reduced chi-square exceeds the misfit threshold (5): quote the read-outs."""
    @property
    def filter_detected(self) -> bool: ...
    @property
    def filtered_points(self) -> int: ...
    @property
    def sample_lag1(self) -> float: ...
    @property
    def fit_taus_s(self) -> tuple[float, float]: ...
    @property
    def term_taus_s(self) -> dict[str, tuple[float, float]]: ...
    def quote(self, term: str) -> dict[str, Any]:
        """The figure to quote for a term: value, sigma, interval (2 sigma), at_most, from."""
    @overload
    def model_deviation(self, tau_s: float) -> float: ...
    @overload
    def model_deviation(self, tau_s: ArrayLike) -> FloatArray: ...
    def term_deviation(self, term: str, tau_s: ArrayLike) -> FloatArray: ...

def noise_terms(
    data: ArrayLike | AllanResult,
    tau0_s: float | None = None,
    taus: str | Sequence[float] = "octave",
    min_clusters: float = ...,
    terms: Sequence[str] | None = None,
) -> NoiseTerms:
    """IEEE 952 terms with 1-sigma, fitted to the oadev of rates `data` ((N,), every tau0_s s) or to
    an adev / oadev / totdev AllanResult. `terms` limits the fit to the named terms. The default of
    min_clusters: noise_terms_options()."""

def noise_terms_options() -> dict[str, tuple[Any, str]]:
    """{name: (default, description)} of the noise fit's options from the library's option table."""

def record_length(
    random_walk: float,
    bias_instability: float,
    rate_random_walk: float,
    tau0_s: float,
    precision: float = 0.25,
) -> dict[str, float]:
    """How long a static log must be (s) to resolve each term to a relative 2-sigma interval
    `precision`, from a first log's or a data sheet's figures (SI; 0 for a term the sensor lacks):
    random_walk_s, bias_instability_s, bias_instability_tau_s, rate_random_walk_s,
    rate_random_walk_tau_s (nan: nothing to resolve)."""
