"""Calibration: file round trip, named coefficients, evaluation, and correct() against `imufit apply`."""

import pathlib

import numpy as np
import pytest

import imufit

# Relative, worst case: the same arithmetic in another order (numpy's polynomial vs Horner).
EVALUATION_TOLERANCE = 1e-12


def same_bits(a, b):
    a, b = np.ascontiguousarray(a, dtype=np.float64), np.ascontiguousarray(b, dtype=np.float64)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


def test_round_trip_is_bit_exact(fixtures, tmp_path):
    cal = imufit.Calibration.load(fixtures / "mems_truth.yaml")
    path = tmp_path / "copy.yaml"
    cal.save(path)
    again = imufit.Calibration.load(path)
    for sensor in ("gyro", "accel"):
        assert same_bits(cal.parameters(sensor), again.parameters(sensor))
    assert again.serial == cal.serial == "MEMS-TRUTH-0001"
    assert again.fit_temp_range_c == cal.fit_temp_range_c
    assert again.to_yaml() == cal.to_yaml()


def test_named_coefficients_follow_the_parameter_layout(fixtures):
    cal = imufit.Calibration.load(fixtures / "mems_truth.yaml")
    gyro = cal.gyro
    assert {k: v.shape for k, v in gyro.items()} == {
        "bias": (3, 4), "scale": (3, 4), "misalignment": (6, 4), "g_sensitivity": (9, 4)}
    assert set(cal.accel) == {"bias", "scale", "misalignment"}
    flat = np.concatenate([gyro[g] for g in ("bias", "scale", "misalignment", "g_sensitivity")]).ravel()
    assert same_bits(flat, cal.parameters("gyro"))
    assert imufit.COEFFICIENT_NAMES[0] == "bias.x" and imufit.COEFFICIENT_NAMES[-1] == "g_sensitivity.zz"
    # The file's own text: gyro bias x is [23.4, 0.118, -0.00092, 1.35e-05].
    assert gyro["bias"][0].tolist() == [23.4, 0.118, -0.00092, 1.35e-05]


def test_set_coefficients_and_identity():
    cal = imufit.Calibration()
    assert cal.gyro["scale"][:, 0].tolist() == [1.0, 1.0, 1.0]
    omega, accel = cal.correct(25.0, [1.0, 2.0, 3.0], [4.0, 5.0, 6.0])
    assert omega.tolist() == [1.0, 2.0, 3.0] and accel.tolist() == [4.0, 5.0, 6.0]
    bias = np.arange(12.0).reshape(3, 4)
    cal.set_coefficients("gyro", "bias", bias)
    assert same_bits(cal.gyro["bias"], bias)
    with pytest.raises(imufit.InputError, match="shape"):
        cal.set_coefficients("gyro", "bias", np.zeros((2, 4)))
    with pytest.raises(imufit.InputError, match="g_sensitivity"):
        cal.set_coefficients("accel", "g_sensitivity", np.zeros((9, 4)))


def test_evaluate_is_the_cubic_in_dt(fixtures):
    cal = imufit.Calibration.load(fixtures / "mems_truth.yaml")
    temps = np.array([-40.0, 0.0, 25.0, 61.5, 85.0])
    at = cal.evaluate(temps)
    dt = temps - cal.reference_temp_c
    for sensor, coefficients in (("gyro", cal.gyro), ("accel", cal.accel)):
        for group in ("bias", "scale"):
            expected = np.stack([np.polynomial.polynomial.polyval(dt, c) for c in coefficients[group]], axis=1)
            np.testing.assert_allclose(at[sensor][group], expected, rtol=EVALUATION_TOLERANCE)
        m = at[sensor]["misalignment"]
        assert m.shape == (5, 3, 3)
        assert np.all(m[:, [0, 1, 2], [0, 1, 2]] == 1.0)
        xy = np.polynomial.polynomial.polyval(dt, coefficients["misalignment"][0])
        np.testing.assert_allclose(m[:, 0, 1], xy, rtol=EVALUATION_TOLERANCE)
    assert at["gyro"]["g_sensitivity"].shape == (5, 3, 3)
    assert same_bits(cal.evaluate(25.0)["gyro"]["bias"], cal.gyro["bias"][:, 0])


def test_correct_is_bit_exact_with_imufit_apply(fixtures, tmp_path, run_imufit):
    samples_path = fixtures / "mems_6pos_soak.csv.gz"
    output = tmp_path / "corrected.csv"
    run_imufit("apply", "--calibration", fixtures / "mems_truth.yaml", "--samples", samples_path, "-o", output)
    applied = imufit.read_samples(output)
    raw = imufit.read_samples(samples_path)
    cal = imufit.Calibration.load(fixtures / "mems_truth.yaml")
    omega, accel = cal.correct(raw["temp_c"], raw["gyro"], raw["accel"])
    assert len(omega) == 26950
    assert same_bits(omega, applied["gyro"])
    assert same_bits(accel, applied["accel"])
    assert same_bits(raw["time_s"], applied["time_s"])
    # Views, other dtypes and lists give the same numbers.
    omega32, _ = cal.correct(raw["temp_c"][::2].copy(), raw["gyro"][::2], raw["accel"][::2].tolist())
    assert same_bits(omega32, omega[::2])


def test_forward_inverts_correct(fixtures):
    cal = imufit.Calibration.load(fixtures / "mems_truth.yaml")
    rng = np.random.default_rng(7)
    temps = rng.uniform(-40, 85, 1000)
    omega = rng.normal(0, 3, (1000, 3))
    accel = rng.normal(0, 9.8, (1000, 3))
    gyro_raw, accel_raw = cal.forward(temps, omega, accel)
    omega_hat, accel_hat = cal.correct(temps, gyro_raw, accel_raw)
    np.testing.assert_allclose(omega_hat, omega, rtol=0, atol=1e-12)
    np.testing.assert_allclose(accel_hat, accel, rtol=0, atol=1e-12)


def test_correct_refuses_mismatched_shapes():
    cal = imufit.Calibration()
    with pytest.raises(ValueError, match=r"gyro_raw must have shape \(N, 3\)"):
        cal.correct(np.zeros(4), np.zeros((4, 2)), np.zeros((4, 3)))
    with pytest.raises(imufit.InputError, match="accel_raw has shape"):
        cal.correct(np.zeros(4), np.zeros((4, 3)), np.zeros((5, 3)))
    with pytest.raises(imufit.InputError, match=r"temp_c must be a number or have shape \(4,\)"):
        cal.correct(np.zeros(3), np.zeros((4, 3)), np.zeros((4, 3)))


def test_bad_calibration_file_raises_input_error_with_location(fixtures, tmp_path):
    text = (fixtures / "mems_truth.yaml").read_text().replace("x: [23.4,", 'x: ["23.4.1",', 1)
    assert text != (fixtures / "mems_truth.yaml").read_text()
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(imufit.InputError) as error:
        imufit.Calibration.load(path)
    assert isinstance(error.value, ValueError)
    assert error.value.file == str(path)
    assert error.value.line > 0
    assert str(error.value).startswith(f"{path}:{error.value.line}:")
    with pytest.raises(imufit.InputError, match="missing.yaml"):
        imufit.Calibration.load(tmp_path / "missing.yaml")


def test_samples_round_trip(fixtures, tmp_path):
    raw = imufit.read_samples(fixtures / "mems_6pos_soak.csv.gz")
    path = tmp_path / "copy.csv.gz"
    imufit.write_samples(path, raw, comment="a copy")
    again = imufit.read_samples(path)
    assert set(again) == set(raw)
    for key in raw:
        assert raw[key].tobytes() == again[key].tobytes(), key


def test_the_fit_record_is_typed_and_the_stub_names_every_key(fixtures, tmp_path):
    import ast

    result = imufit.fit(fixtures / "plan_6pos.yaml", fixtures / "mems_6pos_soak.csv.gz")
    path = tmp_path / "cal.yaml"
    result.calibration.save(path)
    record = imufit.Calibration.load(path).fit
    assert record.samples_read == result.diagnostics["samples_read"] == 26950
    assert record.windows_used == result.diagnostics["windows_used"]
    assert record.distinct_temperatures_c == result.diagnostics["distinct_temperatures_c"].tolist()
    assert record.termination == result.diagnostics["termination"]
    assert record.g_sensitivity_fitted is True and record.held == [] and record.held_values is None
    assert len(record.samples_sha256) == 64 and record.missing_segments == 0
    assert imufit.Calibration.load(path).check is None
    # A calibration without a fit: block (a truth file) has no record.
    assert imufit.Calibration.load(fixtures / "mems_truth.yaml").fit is None
    # The stub declares the module's attributes, no more, no fewer.
    stub = ast.parse((pathlib.Path(imufit.__file__).parent / "__init__.pyi").read_text())
    for name in ("FitRecord", "FieldRecord", "CheckRecord"):
        declared = next(node for node in stub.body if isinstance(node, ast.ClassDef) and node.name == name)
        annotated = {n.target.id for n in declared.body if isinstance(n, ast.AnnAssign)}
        assert annotated == {a for a in dir(getattr(imufit, name)) if not a.startswith("_")}, name
