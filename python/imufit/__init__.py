"""imufit: IMU thermal calibration from Python.

The same C++ libraries as the ``imufit`` command (the shared correction model, the thermal fit,
the simulator and the Allan analysis), on numpy arrays, so that a notebook and the factory give
the same numbers. Units are SI unless a name says otherwise (``temp_c``, ``rate_hz``); raw sensor
outputs are in the unit's own units. See docs/python.md.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Mapping
from typing import Any

from ._imufit import (
    COEFFICIENT_NAMES,
    AllanResult,
    Calibration,
    CheckRecord,
    FieldRecord,
    FitError,
    FitRecord,
    InputError,
    NoiseTerms,
    PlanMismatchError,
    UndeterminedError,
    __version__,
    _fit,
    _fit_field,
    allan,
    allan_options,
    export,
    export_options,
    fit_field_options,
    fit_options,
    noise_terms,
    noise_terms_options,
    plan_check,
    plan_check_options,
    plan_design,
    plan_design_options,
    read_samples,
    record_length,
    simulate,
    simulate_options,
    write_samples,
)

__all__ = [
    "COEFFICIENT_NAMES",
    "AllanResult",
    "Calibration",
    "CheckRecord",
    "FieldFitResult",
    "FieldRecord",
    "FitError",
    "FitRecord",
    "FitResult",
    "InputError",
    "NoiseTerms",
    "PlanMismatchError",
    "UndeterminedError",
    "__version__",
    "allan",
    "allan_options",
    "export",
    "export_options",
    "fit",
    "fit_field",
    "fit_field_options",
    "fit_options",
    "noise_terms",
    "noise_terms_options",
    "plan_check",
    "plan_check_options",
    "plan_design",
    "plan_design_options",
    "read_samples",
    "record_length",
    "simulate",
    "simulate_options",
    "write_samples",
]


@dataclasses.dataclass
class FitResult:
    """What imufit.fit() returns: the calibration, the 1-sigma of its coefficients, diagnostics."""

    calibration: Calibration
    sigma: dict[str, dict[str, Any]]
    diagnostics: dict[str, Any]


def fit(plan: str | os.PathLike[str] | Mapping[str, Any], samples: str | os.PathLike[str] | Mapping[str, Any], **options: Any) -> FitResult:
    """Fits the thermal model to a rate-table run, as ``imufit fit`` does (the same library call).

    ``plan`` is a plan YAML path or the plan as a dict (its YAML as a mapping); ``samples`` a
    samples CSV path or arrays ({time_s, temp_c, gyro, accel; segment and serial optional}, as
    simulate() and read_samples() return), fitted as they are, through the same reader as a file
    (its checks, windows and labelling) with nothing written; the serial in ``samples["serial"]``
    is the unit's, as a file's ``# serial:`` line. ``options``: see fit_options(). Raises InputError (a ValueError) on bad input,
    UndeterminedError naming what is missing when the run does not determine the model,
    PlanMismatchError when a run without a segment column does not match the plan, and FitError
    when the solver does not converge.
    """
    if isinstance(plan, Mapping):
        plan = dict(plan)
    if isinstance(samples, Mapping):
        samples = dict(samples)
    return FitResult(**_fit(plan, samples, options))


@dataclasses.dataclass
class FieldFitResult:
    """What imufit.fit_field() returns: the calibration by hand, the 1-sigma of its coefficients and
    the session's summary."""

    calibration: Calibration
    sigma: dict[str, dict[str, Any]]
    summary: dict[str, Any]


def fit_field(samples: str | os.PathLike[str] | Mapping[str, Any], **options: Any) -> FieldFitResult:
    """Fits a session by hand, as ``imufit fit --field`` does (the same library call; docs/field.md).

    ``samples`` is a samples CSV path (a log without a segment column) or arrays ({time_s, temp_c,
    gyro, accel; serial optional}, as simulate() and read_samples() return), fitted as they are.
    ``options``: see fit_field_options() (gravity_mps2 or latitude_deg/height_m, temp_c for a log
    without a thermometer, bias_temp_order, ...). The calibration is in the body frame
    ``accelerometer_xy`` and is used as any other (correct(), save(), export()). Raises InputError on
    bad input (a table fit's option included), UndeterminedError naming what the session lacks in
    the words ``imufit fit --field`` prints, and FitError when the solver does not converge.
    """
    if isinstance(samples, Mapping):
        samples = dict(samples)
    return FieldFitResult(**_fit_field(samples, options))
