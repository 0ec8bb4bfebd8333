"""fit() and simulate() against `imufit fit` / `imufit simulate`, known truth, and the errors."""

import numpy as np
import pytest

import imufit

# Relative, worst case, per parameter: the same library call; only the solver's threads may
# reorder sums (scale: the largest magnitude of the coefficient's group, so near-zero terms
# are compared at the group's precision).
CLI_TOLERANCE = 1e-12
# Worst-case recovery of the simulated truth, in the fit's own 1-sigma.
RECOVERY_SIGMAS = 5.0

SOAK = dict(soak_temps_c=[-35, -10, 25, 55, 80], rate_hz=50, dwell_s=5, transition_s=1,
            gyro_noise_density=8.7e-5, accel_noise_density=1.5e-3, temp_noise_c=0.05, seed=3)
SOAK_CLI = ["--temps=-35,-10,25,55,80", "--rate", 50, "--dwell", 5, "--transition", 1,
            "--gyro-noise-density", 8.7e-5, "--accel-noise-density", 1.5e-3, "--temp-noise", 0.05, "--seed", 3]


def assert_parameters_close(a, b):
    for sensor in ("gyro", "accel"):
        ga, gb = a[sensor], b[sensor]
        assert set(ga) == set(gb)
        for group in ga:
            scale = np.max(np.abs(gb[group]), axis=0)  # per power of dT
            difference = np.abs(ga[group] - gb[group])
            assert np.all(difference <= CLI_TOLERANCE * scale), (sensor, group, difference / scale)


def test_fit_matches_imufit_fit(fixtures, tmp_path, run_imufit):
    plan, samples = fixtures / "plan_6pos.yaml", fixtures / "mems_6pos_soak.csv.gz"
    run_imufit("fit", "--plan", plan, "--samples", samples, "-o", tmp_path / "cli.yaml", "-q")
    cli = imufit.Calibration.load(tmp_path / "cli.yaml")
    result = imufit.fit(plan, samples)
    cal = result.calibration
    assert_parameters_close({"gyro": cal.gyro, "accel": cal.accel}, {"gyro": cli.gyro, "accel": cli.accel})
    assert_parameters_close(result.sigma, cli.sigma)
    assert_parameters_close(cal.sigma, cli.sigma)
    assert cal.fit_temp_range_c == cli.fit_temp_range_c
    assert cal.software == cli.software
    d = result.diagnostics
    assert d["termination"] and d["iterations"] > 0
    assert d["windows_used"] == len(d["residuals"]["window"]) > 0
    assert d["samples_read"] == 26950
    assert d["residuals"]["gyro_radps"].shape == (d["windows_used"], 3)
    assert "converged" in d["brief_report"]


def test_fit_options_map_onto_the_command(fixtures, tmp_path, run_imufit):
    plan, samples = fixtures / "plan_6pos.yaml", fixtures / "mems_6pos_soak.csv.gz"
    run_imufit("fit", "--plan", plan, "--samples", samples, "-o", tmp_path / "cli.yaml", "-q", "--gyro-temp-order", 2,
               "--no-g-sensitivity", "--loss", "cauchy", "--trim", 1.0, "--window-min-samples", 30,
               "--gyro-bias-stability-dph", 36)
    cli = imufit.Calibration.load(tmp_path / "cli.yaml")
    result = imufit.fit(plan, samples, gyro_temp_order=2, fit_g_sensitivity=False, loss="cauchy", trim_s=1.0,
                        window_min_samples=30, gyro_bias_stability_radps=36 * np.pi / 180 / 3600)
    cal = result.calibration
    assert np.all(cal.gyro["g_sensitivity"] == 0) and np.all(cal.gyro["bias"][:, 3] == 0)
    assert_parameters_close({"gyro": cal.gyro, "accel": cal.accel}, {"gyro": cli.gyro, "accel": cli.accel})
    assert_parameters_close(result.sigma, cli.sigma)
    defaults = imufit.fit_options()
    assert defaults["loss"][0] == "huber" and defaults["gyro_temp_order"][0] == 3
    assert defaults["fit"][0] == "all"


def test_fit_a_subset_holds_the_rest(fixtures, tmp_path, run_imufit):
    plan, samples = fixtures / "plan_6pos.yaml", fixtures / "mems_6pos_soak.csv.gz"
    prior = fixtures / "mems_truth.yaml"
    run_imufit("fit", "--plan", plan, "--samples", samples, "-o", tmp_path / "cli.yaml", "-q", "--fit", "gyro-bias,accel",
               "--prior", prior)
    cli = imufit.Calibration.load(tmp_path / "cli.yaml")
    result = imufit.fit(plan, samples, fit="gyro-bias,accel", prior=prior)
    cal = result.calibration
    held = imufit.Calibration.load(prior)
    np.testing.assert_allclose(cal.gyro["scale"], held.gyro["scale"], rtol=1e-9)
    assert np.all(result.sigma["gyro"]["scale"] == 0)
    # Without a prior the held gyro scale would be 1 raw per rad/s: refused, naming --prior.
    with pytest.raises(imufit.FitError, match="--prior"):
        imufit.fit(plan, samples, fit="gyro-bias,accel")
    assert_parameters_close({"gyro": cal.gyro, "accel": cal.accel}, {"gyro": cli.gyro, "accel": cli.accel})
    with pytest.raises(ValueError, match="is not a group to fit"):
        imufit.fit(plan, samples, fit="magnetometer")


def test_simulate_matches_imufit_simulate(fixtures, tmp_path, run_imufit):
    plan, truth = fixtures / "plan_6pos.yaml", fixtures / "mems_truth.yaml"
    run_imufit("simulate", "--plan", plan, "--calibration", truth, "-o", tmp_path / "raw.csv",
               "--truth", tmp_path / "truth.csv", "--quantize", *SOAK_CLI)
    cli = imufit.read_samples(tmp_path / "raw.csv")
    cli_truth = imufit.read_samples(tmp_path / "truth.csv")
    run = imufit.simulate(plan, imufit.Calibration.load(truth), quantize=True, **SOAK)
    for key in ("time_s", "temp_c", "segment", "gyro", "accel"):
        assert run[key].tobytes() == cli[key].tobytes(), key
    assert run["omega_true_radps"].tobytes() == cli_truth["gyro"].tobytes()
    assert run["a_true_mps2"].tobytes() == cli_truth["accel"].tobytes()


def test_simulate_with_lost_samples_matches_imufit_simulate(fixtures, tmp_path, run_imufit):
    # Lost samples shorten the arrays; the samples kept are those of the run without losses.
    plan, truth = fixtures / "plan_6pos.yaml", fixtures / "mems_truth.yaml"
    run_imufit("simulate", "--plan", plan, "--calibration", truth, "-o", tmp_path / "raw.csv",
               "--drop-probability", 0.01, "--drop-burst", 2, *SOAK_CLI)
    cli = imufit.read_samples(tmp_path / "raw.csv")
    run = imufit.simulate(plan, truth, drop_probability=0.01, drop_burst=2, **SOAK)
    whole = imufit.simulate(plan, truth, **SOAK)
    assert 0 < len(whole["time_s"]) - len(run["time_s"]) < 0.05 * len(whole["time_s"])
    for key in ("time_s", "gyro", "accel"):
        assert run[key].tobytes() == cli[key].tobytes(), key
    kept = np.isin(whole["time_s"], run["time_s"])
    assert np.array_equal(whole["gyro"][kept], run["gyro"])
    # The fit finds the gaps on the run's time grid (those while the grid is acquired uncounted).
    diagnostics = imufit.fit(plan, run).diagnostics
    lost = len(whole["time_s"]) - len(run["time_s"])
    assert 0.9 * lost <= diagnostics["lost_samples"] <= lost
    assert diagnostics["off_grid_samples"] == 0
    assert "samples lost in" in diagnostics["time_stamp_note"]


def test_fit_of_a_simulated_run_recovers_the_truth(fixtures, tmp_path, run_imufit):
    plan = fixtures / "plan_6pos.yaml"
    truth = imufit.Calibration.load(fixtures / "mems_truth.yaml")
    run = imufit.simulate(plan, truth, **SOAK)
    result = imufit.fit(plan, run)  # arrays in: written to a temporary CSV and fitted
    cal = result.calibration
    temps = np.array([-35.0, -10.0, 25.0, 55.0, 80.0])
    fitted, true = cal.evaluate(temps), truth.evaluate(temps)
    # Bias at the soak temperatures against the truth, in the fit's own sigma of c0 (the sigma of
    # the value at 25 degC; a conservative scale elsewhere is not needed for a 5-sigma bound).
    sigma_c0 = result.sigma["gyro"]["bias"][:, 0]
    error = np.abs(fitted["gyro"]["bias"][2] - true["gyro"]["bias"][2])
    assert np.all(error < RECOVERY_SIGMAS * sigma_c0), (error, sigma_c0)
    fitted_c0 = cal.parameters("gyro")
    true_c0 = truth.parameters("gyro")
    sigma = np.concatenate([result.sigma["gyro"][g] for g in ("bias", "scale", "misalignment", "g_sensitivity")]).ravel()
    assert np.all(np.abs(fitted_c0 - true_c0)[::4] < RECOVERY_SIGMAS * sigma[::4])
    # The same run from the command's file gives the same calibration.
    imufit.write_samples(tmp_path / "run.csv", run)
    again = imufit.fit(plan, tmp_path / "run.csv").calibration
    assert_parameters_close({"gyro": cal.gyro, "accel": cal.accel}, {"gyro": again.gyro, "accel": again.accel})


def test_undetermined_run_raises_naming_what_is_missing(fixtures):
    plan = fixtures / "plan_6pos.yaml"
    run = imufit.simulate(plan, fixtures / "mems_truth.yaml", soak_temps_c=[25.0], rate_hz=50, dwell_s=2,
                          transition_s=1)
    with pytest.raises(imufit.UndeterminedError) as error:
        imufit.fit(plan, run)
    assert isinstance(error.value, imufit.FitError) and isinstance(error.value, RuntimeError)
    assert not isinstance(error.value, ValueError)
    assert error.value.missing
    for finding in error.value.missing:
        assert finding in str(error.value)
    assert "\n" not in str(error.value), "one line, as the command line says it"
    assert "the run:" in str(error.value)
    assert "temperature" in " ".join(error.value.missing)
    # The same run fits when the model asks only for what it has.
    fitted = imufit.fit(plan, run, gyro_temp_order=0, accel_temp_order=0)
    assert np.all(fitted.calibration.gyro["bias"][:, 1:] == 0)


def test_bad_input_raises_input_error_with_file_and_line(fixtures, tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("time_s,temp_c,segment,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n"
                   "0,25,1,1,2,3,4,5,6\n"
                   "0.01,25,1,1,2.2.2,3,4,5,6\n")
    with pytest.raises(imufit.InputError) as error:
        imufit.fit(fixtures / "plan_6pos.yaml", bad)
    assert isinstance(error.value, ValueError)
    assert (error.value.file, error.value.line, error.value.column) == (str(bad), 3, 5)
    assert str(error.value).startswith(f"{bad}:3:5: ")
    assert "2.2.2" in error.value.message
    with pytest.raises(imufit.InputError, match="plan"):
        imufit.fit(tmp_path / "no_plan.yaml", bad)


def test_bad_options(fixtures):
    plan, samples = fixtures / "plan_6pos.yaml", fixtures / "mems_6pos_soak.csv.gz"
    with pytest.raises(TypeError, match="unexpected keyword argument 'gyro_order'.*gyro_temp_order"):
        imufit.fit(plan, samples, gyro_order=2)
    with pytest.raises(imufit.InputError, match="imufit.fit"):
        imufit.fit(plan, samples, gyro_temp_order=7)
    with pytest.raises(imufit.InputError, match="huber"):
        imufit.fit(plan, samples, loss="l1")
    with pytest.raises(imufit.InputError, match="wrong type"):
        imufit.fit(plan, samples, trim_s="long")
    with pytest.raises(TypeError, match="unexpected keyword argument 'temps'"):
        imufit.simulate(plan, imufit.Calibration(), temps=[1])
    with pytest.raises(imufit.InputError, match="imufit.simulate"):
        imufit.simulate(plan, imufit.Calibration(), rate_hz=-1)


def test_unlabelled_run_is_segmented_as_the_command_does(fixtures, tmp_path, run_imufit):
    plan = fixtures / "plan_6pos.yaml"
    run = imufit.simulate(plan, fixtures / "mems_truth.yaml", **SOAK)
    unlabelled = {key: run[key] for key in ("time_s", "temp_c", "gyro", "accel")}  # no segment column
    imufit.write_samples(tmp_path / "unlabelled.csv", unlabelled)
    run_imufit("fit", "--plan", plan, "--samples", tmp_path / "unlabelled.csv", "-o", tmp_path / "cli.yaml", "-q")
    cli = imufit.Calibration.load(tmp_path / "cli.yaml")
    cal = imufit.fit(plan, unlabelled).calibration
    assert_parameters_close({"gyro": cal.gyro, "accel": cal.accel}, {"gyro": cli.gyro, "accel": cli.accel})
    # Against a plan it does not follow: the command exits 1, the module raises PlanMismatchError.
    assert run_imufit("fit", "--plan", fixtures / "plan_24pos.yaml", "--samples", tmp_path / "unlabelled.csv",
                      "-o", tmp_path / "no.yaml", check=False).returncode == 1
    with pytest.raises(imufit.PlanMismatchError) as error:
        imufit.fit(fixtures / "plan_24pos.yaml", unlabelled)
    assert isinstance(error.value, imufit.FitError) and str(error.value)
