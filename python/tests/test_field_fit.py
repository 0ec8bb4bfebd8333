"""imufit.fit_field(): a session by hand fitted from Python, as `imufit fit --field` fits it (the
same coefficients from the file and from its arrays), the same refusal of an undetermined session
in the command's words, and the calibration used downstream: its Kalibr export (the noise of a
static recording added with `export --noise`) read by PyYAML's safe_load (Kalibr's reader) and
applied through Kalibr's scale-misalignment model."""

import numpy as np
import pytest
import yaml

import imufit

# The simulated unit's noise (fixtures/mems_truth.yaml with these densities), and a session by hand
# of it as tests/cli_field_test.cc simulates one (12 poses, 100 Hz, counts, stamp jitter).
GYRO_NOISE_DENSITY = 2e-4  # rad/s/sqrt(Hz)
ACCEL_NOISE_DENSITY = 1e-3  # m/s^2/sqrt(Hz)
NOISE = ["--rate", "100", "--gyro-noise-density", str(GYRO_NOISE_DENSITY), "--accel-noise-density",
         str(ACCEL_NOISE_DENSITY), "--quantize"]
DRIVER = {"gyro_raw_per_radps": 939.65, "accel_raw_per_mps2": 208.838}
# Kalibr's noise densities against the simulated ones: a 300 s static log's estimate (relative).
NOISE_DENSITY_RTOL = 0.05
# Kalibr's model applied to the pose means against imufit's correction: the export at one
# temperature holds the whole model (its reported loss is ~1e-13); absolute, SI.
KALIBR_ATOL = 1e-9


def _session(run_imufit, fixtures, path, *extra):
    run_imufit("simulate", "--field", "--calibration", fixtures / "mems_truth.yaml", "-o", path, "--temps", "25",
               "--dwell", "3", *NOISE, "--time-jitter-s", "0.002", "--drop-probability", "0.005", "--seed", "12",
               *extra)
    return path


def test_fit_field_gives_the_coefficients_of_the_command(fixtures, tmp_path, run_imufit):
    session = _session(run_imufit, fixtures, tmp_path / "session.csv", "--serial", "SN-HAND-2")
    command = tmp_path / "command.yaml"
    run_imufit("fit", "--field", "--samples", session, "-o", command, "-q")
    expected = imufit.Calibration.load(command)
    from_file = imufit.fit_field(session)
    from_arrays = imufit.fit_field(imufit.read_samples(session))
    for result in (from_file, from_arrays):
        assert result.calibration.body_frame == "accelerometer_xy"
        for sensor in ("gyro", "accel"):
            np.testing.assert_array_equal(result.calibration.parameters(sensor), expected.parameters(sensor))
            for group, sigma in expected.sigma[sensor].items():
                np.testing.assert_array_equal(result.sigma[sensor][group], sigma)
    summary = from_file.summary
    assert summary["status"] == "converged" and summary["undetermined"] == []
    assert summary["serial"] == "SN-HAND-2" and from_file.calibration.fit.field.gravity_source == "standard"
    assert len(summary["poses"]["start_s"]) == expected.fit.field.poses == 12
    assert len(summary["turns"]["angle_rad"]) == expected.fit.field.turns == 11
    assert summary["poses"]["accel_mean"].shape == (12, 3) and summary["poses"]["up"].shape == (12, 3)
    assert summary["accel_norm_rms_mps2"] == expected.fit.field.accel_norm_rms_mps2
    assert summary["direction_rms_rad"] == expected.fit.field.gravity_direction_rms_rad
    assert summary["noise_scale"] == (1.0, 1.0, 1.0)
    # Local gravity from the site, as --latitude gives it: recorded with the site.
    site = imufit.fit_field(session, latitude_deg=48.1, height_m=520.0)
    assert site.calibration.fit.field.gravity_source == "latitude"
    assert site.calibration.fit.field.latitude_deg == 48.1
    assert site.calibration.fit.field.gravity_mps2 != expected.fit.field.gravity_mps2


def test_fit_field_refuses_an_undetermined_session_in_the_command_words(fixtures, tmp_path, run_imufit):
    session = _session(run_imufit, fixtures, tmp_path / "session.csv")
    cut = tmp_path / "cut.csv"
    cut.write_text("".join(session.read_text().splitlines(keepends=True)[:1800]))  # the first third
    command = run_imufit("fit", "--field", "--samples", cut, "-o", tmp_path / "cal.yaml", check=False)
    assert command.returncode == 1
    with pytest.raises(imufit.UndeterminedError) as refused:
        imufit.fit_field(cut)
    assert any("poses at rest, needs at least 9" in finding for finding in refused.value.missing)
    # The command's line is "imufit: <file>: <the same words>, nothing written".
    assert f"imufit: {refused.value}, nothing written" in command.stderr
    assert refused.value.diagnostics["status"] == "undetermined"


def test_fit_field_options_and_refusals():
    assert "gravity_mps2" in imufit.fit_field_options() and "temp_c" in imufit.fit_field_options()
    assert "validate" not in imufit.fit_field_options()
    with pytest.raises(imufit.InputError, match="validate is an option of a table fit"):
        imufit.fit_field("unused.csv", validate=True)
    with pytest.raises(imufit.InputError, match="gravity_mps2 and latitude_deg both given"):
        imufit.fit_field("unused.csv", gravity_mps2=9.81, latitude_deg=45.0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'gravity'"):
        imufit.fit_field("unused.csv", gravity=9.81)


def test_field_calibration_to_kalibr(fixtures, tmp_path, run_imufit):
    """The user's way: a session by hand and a static recording; fit, the noise, the Kalibr file."""
    session = _session(run_imufit, fixtures, tmp_path / "session.csv")
    plan = tmp_path / "static_plan.yaml"
    plan.write_text("format: imufit-plan\nversion: 1\ngravity_mps2: 9.80665\nsegments:\n  - {id: 1, up: [0, 0, 1]}\n")
    static = tmp_path / "static.csv.gz"
    run_imufit("simulate", "-p", plan, "-c", fixtures / "mems_truth.yaml", "-o", static, "--temps", "25",
               "--dwell", "300", *NOISE, "--seed", "3")
    fit = imufit.fit_field(session)
    calibration = tmp_path / "cal.yaml"
    fit.calibration.save(calibration)
    noise = tmp_path / "noise.yaml"
    run_imufit("allan", "-q", "-s", static, "--calibration", calibration, "-o", tmp_path / "allan.csv",
               "--columns", "gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z", "--noise-yaml", noise)
    imu = tmp_path / "imu.yaml"
    run_imufit("export", "-q", "-c", calibration, "--noise", noise, "-f", "kalibr", "--gyro-raw-per-radps",
               DRIVER["gyro_raw_per_radps"], "--accel-raw-per-mps2", DRIVER["accel_raw_per_mps2"], "-o", imu)
    text = imu.read_text()
    kalibr = yaml.safe_load(text)
    np.testing.assert_allclose(kalibr["gyroscope_noise_density"], GYRO_NOISE_DENSITY, rtol=NOISE_DENSITY_RTOL)
    np.testing.assert_allclose(kalibr["accelerometer_noise_density"], ACCEL_NOISE_DENSITY, rtol=NOISE_DENSITY_RTOL)
    assert kalibr["update_rate"] == 100 and kalibr["model"] == "scale-misalignment"
    # The same file as the noise block appended to the calibration by hand.
    appended = tmp_path / "appended.yaml"
    appended.write_text(calibration.read_text() + noise.read_text())
    by_hand = tmp_path / "by_hand.yaml"
    run_imufit("export", "-q", "-c", appended, "-f", "kalibr", "--gyro-raw-per-radps", DRIVER["gyro_raw_per_radps"],
               "--accel-raw-per-mps2", DRIVER["accel_raw_per_mps2"], "-o", by_hand)
    assert yaml.safe_load(by_hand.read_text()) == kalibr
    # Kalibr's model (IccSensors.py): d_accel = M_a a_i + b_a, d_gyro = M_g C w_i + A C a_i + b_g, in
    # the driver's SI; i = C_i_b * body (stated in the header). Inverted at the session's poses, it
    # gives what imufit's correction gives.
    c_i_b = np.array(yaml.safe_load(next(line[len("# C_i_b:"):] for line in text.splitlines()
                                         if line.startswith("# C_i_b:"))))
    poses = fit.summary["poses"]
    omega_hat, a_hat = fit.calibration.correct(poses["temp_c"], poses["gyro_mean"], poses["accel_mean"])
    m_a, b_a = np.array(kalibr["accelerometers"]["M"]), np.array(kalibr["accelerometers"]["b"])
    gyro = kalibr["gyroscopes"]
    m_g, a_g, c_g, b_g = (np.array(gyro[key]) for key in ("M", "A", "C_gyro_i", "b"))
    d_accel = poses["accel_mean"] / DRIVER["accel_raw_per_mps2"]
    d_gyro = poses["gyro_mean"] / DRIVER["gyro_raw_per_radps"]
    a_i = np.linalg.solve(m_a, (d_accel - b_a).T).T
    w_i = (c_g.T @ np.linalg.solve(m_g, (d_gyro - b_g - (a_g @ c_g @ a_i.T).T).T)).T
    np.testing.assert_allclose(a_i, a_hat @ c_i_b.T, atol=KALIBR_ATOL)
    np.testing.assert_allclose(w_i, omega_hat @ c_i_b.T, atol=KALIBR_ATOL)
    # |a| = g at every pose through Kalibr's model (the session's own residual: well under 1 mg).
    assert np.max(np.abs(np.linalg.norm(a_i, axis=1) - 9.80665)) < 1e-3 * 9.80665
