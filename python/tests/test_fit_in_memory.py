"""fit() on arrays and on a plan dict: no file written, the serial kept, errors naming fit(), and
no solver log on the notebook's output."""

import numpy as np
import pytest

import imufit
from test_fit import SOAK, assert_parameters_close


@pytest.fixture(scope="module")
def run(fixtures):
    return imufit.simulate(fixtures / "plan_6pos.yaml", fixtures / "mems_truth.yaml", **SOAK)


def test_arrays_are_fitted_without_a_file(fixtures, tmp_path, run, monkeypatch):
    plan = fixtures / "plan_6pos.yaml"
    imufit.write_samples(tmp_path / "run.csv", run)
    from_file = imufit.fit(plan, tmp_path / "run.csv").calibration

    def no_file(*args, **kwargs):
        raise AssertionError("fit() on arrays wrote a file")

    monkeypatch.setattr(imufit, "write_samples", no_file)
    monkeypatch.setattr("tempfile.TemporaryDirectory", no_file)
    monkeypatch.setattr("tempfile.mkstemp", no_file)
    result = imufit.fit(plan, run)
    cal = result.calibration
    # The same doubles through the same reader: the file's calibration.
    assert_parameters_close({"gyro": cal.gyro, "accel": cal.accel}, {"gyro": from_file.gyro, "accel": from_file.accel})
    assert result.diagnostics["samples_read"] == len(run["time_s"])
    assert cal.fit.samples == "imufit.fit samples"
    assert len(cal.fit.samples_sha256) == 64
    # Unlabelled arrays are segmented in memory, as the file is.
    unlabelled = {key: run[key] for key in ("time_s", "temp_c", "gyro", "accel")}
    again = imufit.fit(plan, unlabelled).calibration
    assert again.fit.segments_found_in_data >= 18


def test_the_serial_of_the_samples_is_kept(fixtures, tmp_path, run):
    plan = fixtures / "plan_6pos.yaml"
    imufit.write_samples(tmp_path / "run.csv", run, comment="serial: SN-0042")
    read = imufit.read_samples(tmp_path / "run.csv")
    assert read["serial"] == "SN-0042"
    assert imufit.fit(plan, read).calibration.serial == "SN-0042"
    # Written again, the serial travels with the arrays.
    imufit.write_samples(tmp_path / "copy.csv", read)
    assert imufit.read_samples(tmp_path / "copy.csv")["serial"] == "SN-0042"


def test_the_plan_may_be_a_dict(fixtures, run):
    yaml = pytest.importorskip("yaml", reason="PyYAML reads the plan file into a dict for this test")
    plan_path = fixtures / "plan_6pos.yaml"
    plan = yaml.safe_load(plan_path.read_text())
    by_path = imufit.fit(plan_path, run).calibration
    by_dict = imufit.fit(plan, run).calibration
    assert_parameters_close({"gyro": by_dict.gyro, "accel": by_dict.accel},
                            {"gyro": by_path.gyro, "accel": by_path.accel})
    assert by_dict.fit.plan == "imufit.fit plan"
    # A bad plan dict is refused by the plan reader, named as fit()'s argument.
    plan["gravity_mps2"] = 5.0
    with pytest.raises(imufit.InputError) as error:
        imufit.fit(plan, run)
    assert str(error.value).startswith("imufit.fit plan:")
    assert "gravity_mps2" in str(error.value)


def test_errors_name_the_function_called(fixtures, run):
    plan = fixtures / "plan_6pos.yaml"
    short = dict(run, gyro=run["gyro"][:-1])
    with pytest.raises(imufit.InputError, match=r"^imufit.fit: gyro has shape"):
        imufit.fit(plan, short)
    with pytest.raises(imufit.InputError, match=r'^imufit.fit: samples has no "accel"'):
        imufit.fit(plan, {key: run[key] for key in ("time_s", "temp_c", "gyro")})
    kelvin = dict(run, temp_c=run["temp_c"] + 273.15)
    with pytest.raises(imufit.InputError, match=r"^imufit.fit samples:1: temp_c: .*kelvin\?"):
        imufit.fit(plan, kelvin)
    milliseconds = dict(run, time_s=run["time_s"] * 1e3)
    with pytest.raises(imufit.InputError, match=r"^imufit.fit samples:17: time_s: .*--time-unit ms"):
        imufit.fit(plan, milliseconds)
    assert imufit.fit(plan, milliseconds, time_unit="ms").calibration.fit.samples_read == len(run["time_s"])
    backwards = dict(run, time_s=run["time_s"][::-1].copy())
    with pytest.raises(imufit.InputError, match=r"^imufit.fit samples:2: time_s: .* does not increase"):
        imufit.fit(plan, backwards)


def test_no_solver_log_reaches_the_notebook(fixtures, run, capfd):
    plan = fixtures / "plan_6pos.yaml"
    imufit.fit(plan, run)
    dead = dict(run, gyro=run["gyro"].copy())
    dead["gyro"][:, 1] = 0.0  # a dead gyro axis: the case that filled a terminal with Ceres's log
    with pytest.raises(imufit.FitError) as error:
        imufit.fit(plan, dead)
    assert "gyro_y" in str(error.value) and "\n" not in str(error.value)
    out, err = capfd.readouterr()
    assert out == "" and err == ""
