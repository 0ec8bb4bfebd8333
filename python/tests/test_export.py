"""imufit.export(): the same bytes and loss as `imufit export` for every format, options by the
names of the command's option table, refusals as InputError naming the option, the PX4 file read
as QGroundControl reads it and the Kalibr file by PyYAML's safe_load (Kalibr's reader)."""

import math

import numpy as np
import pytest
import yaml

import imufit

DRIVER = {"gyro_raw_per_radps": 939.65, "accel_raw_per_mps2": 208.838}
FLAGS = {"gyro_raw_per_radps": "--gyro-raw-per-radps", "accel_raw_per_mps2": "--accel-raw-per-mps2",
         "device_id": "--device-id", "gyro_device_id": "--gyro-device-id", "accel_device_id": "--accel-device-id",
         "instance": "--instance", "envelope_temp_c": "--envelope-temp-c", "temp_c": "--temp-c"}
NOISE = """noise:
  format: imufit-noise
  version: 1
  kalibr:
    gyroscope_noise_density: 0.00026
    gyroscope_random_walk: 2.1e-05
    accelerometer_noise_density: 0.0023
    accelerometer_random_walk: 0.00011
    update_rate: 50
"""


def _args(options):
    args = []
    for key, value in options.items():
        args += [FLAGS[key], ",".join(map(str, value)) if isinstance(value, (list, tuple)) else str(value)]
    return args


def _worst(stdout, sensor):
    for line in stdout.splitlines():
        words = line.split()
        if words[:2] == [sensor, "worst"]:
            return [float(words[3]), float(words[5]), float(words[7])]
    raise AssertionError(stdout)


@pytest.mark.parametrize("format, options", [
    ("c", {}), ("bin", {}), ("json", {}), ("imucal", {"envelope_temp_c": (20, 30)}),
    ("kalibr", DRIVER), ("px4", {**DRIVER, "device_id": 2621474, "instance": 1}),
    ("ardupilot", {**DRIVER, "gyro_device_id": 11, "accel_device_id": 22, "instance": 3}),
])
def test_export_gives_the_bytes_and_loss_of_the_command(fixtures, tmp_path, run_imufit, format, options):
    calibration = tmp_path / "unit.yaml"
    calibration.write_text((fixtures / "mems_truth.yaml").read_text() + NOISE)
    command = run_imufit("export", "-c", calibration, "-f", format, "-o", tmp_path / "command.out", "--force",
                         *_args(options))
    result = imufit.export(calibration, format, output=tmp_path / "python.out", **options)
    written = (tmp_path / "python.out").read_bytes()
    assert result["content"] == written
    # The provenance names the exporting program: "imufit 0.1.0" against "imufit 0.1.0 (Python)".
    assert written.replace(b" (Python)", b"") == (tmp_path / "command.out").read_bytes()
    if result["loss"] is None:
        assert format == "json"
        return
    for sensor, key in (("gyro", "gyro_worst_dps"), ("accel", "accel_worst_mg")):
        np.testing.assert_allclose(result["loss"][key], _worst(command.stdout, sensor), rtol=5e-3, atol=1e-12)
    assert result["loss"]["points"] > 0
    assert "--envelope-temp-c" in result["envelope"]


def test_export_of_a_calibration_in_memory_and_the_files_consumers_read(fixtures, tmp_path):
    unit = imufit.Calibration.load(fixtures / "mems_truth.yaml")
    px4 = imufit.export(unit, "PX4", device_id=7, **DRIVER)
    rows = [line.split("\t") for line in px4["content"].decode().splitlines() if not line.startswith("#")]
    assert all(len(row) == 5 and row[0] == "1" and row[4] in ("6", "9") for row in rows)
    params = {row[2]: float(row[3]) for row in rows}
    assert params["TC_G0_ID"] == params["CAL_ACC0_ID"] == 7
    assert all(math.isfinite(v) for v in params.values())
    assert b"(in memory)" in px4["content"] and b"reboot" in px4["content"]
    (tmp_path / "unit.yaml").write_text((fixtures / "mems_truth.yaml").read_text() + NOISE)
    kalibr = yaml.safe_load(imufit.export(tmp_path / "unit.yaml", "kalibr", **DRIVER)["content"])
    for key in ("accelerometer_noise_density", "gyroscope_noise_density", "update_rate"):
        assert isinstance(kalibr[key], (int, float)) and kalibr[key] > 0, key
    ardupilot = imufit.export(unit, "ardupilot", device_id=7, **DRIVER)
    assert any("80" in w and "TMIN/TMAX" in w for w in ardupilot["warnings"])
    assert not any("exactly 0" in w for w in ardupilot["warnings"])


def test_export_refusals_name_the_option(fixtures):
    cal = fixtures / "mems_truth.yaml"
    with pytest.raises(imufit.InputError, match="--device-id"):
        imufit.export(cal, "px4", **DRIVER)
    with pytest.raises(imufit.InputError, match="--gyro-raw-per-radps"):
        imufit.export(cal, "kalibr")
    with pytest.raises(imufit.InputError, match="instance"):
        imufit.export(cal, "px4", device_id=1, instance="7", **DRIVER)
    with pytest.raises(imufit.InputError, match="is not a format"):
        imufit.export(cal, "mavlink")
    with pytest.raises(imufit.InputError, match="device_id: only px4, ardupilot use it, not json"):
        imufit.export(cal, "json", device_id=5)
    with pytest.raises(imufit.InputError, match="temp_c: only kalibr, imucal use it, not px4"):
        imufit.export(cal, "px4", device_id=5, temp_c=25, **DRIVER)
    with pytest.raises(TypeError, match="unexpected keyword argument 'device'"):
        imufit.export(cal, "px4", device=1)
    assert set(imufit.export_options()) >= {"device_id", "instance", "envelope_temp_c", "full_scale_dps"}
