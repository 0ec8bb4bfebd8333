"""Every machine-readable file imufit writes, read by its consumers' own readers.

PyYAML's `safe_load` (YAML 1.1: what Kalibr reads imu.yaml with) loads every YAML file imufit
writes (a fitted calibration with its noise block, the noise YAML of `imufit allan`, Kalibr's
imu.yaml, the plan of `plan design`, plan check's YAML), and every number in it comes back a
number: no value is a string that reads as a number, a time or a boolean. The JSON export
validates against docs/calibration.schema.json and holds the same values, of the same types, as
PyYAML reads from the YAML. A Latin-1 byte in an input's file name leaves the output valid UTF-8.
"""

import json
import math
import os
import re
import subprocess

import pytest
import yaml

jsonschema = pytest.importorskip("jsonschema")

from conftest import ROOT, _binary  # noqa: E402

SCHEMA = json.loads((ROOT / "docs" / "calibration.schema.json").read_text())

# A number as YAML 1.1 or 1.2 would read it, were it written plain: a string that looks like this
# is a number written as text (what the JSON export did with the fit: block, and what 2e-06 is to
# YAML 1.1). Times and the like are strings by intent; that they are quoted shows in their type:
# str, not datetime.
_NUMBER = re.compile(
    r"[-+]?(\.[0-9]+|[0-9][0-9_]*(\.[0-9_]*)?)([eE][-+]?[0-9]+)?|[-+]?\.(inf|Inf|INF)|\.(nan|NaN|NAN)"
)


def _values(tree, path=""):
    if isinstance(tree, dict):
        for key, value in tree.items():
            assert isinstance(key, str), f"{path}: key {key!r} is not a string"
            yield from _values(value, f"{path}.{key}")
    elif isinstance(tree, list):
        for i, value in enumerate(tree):
            yield from _values(value, f"{path}[{i}]")
    else:
        yield path, tree


def _assert_typed(tree, what):
    """No number written as text; no date or time objects (a time written plain)."""
    numbers = 0
    for path, value in _values(tree):
        assert isinstance(value, (str, int, float, bool, type(None))), f"{what}{path}: {value!r} ({type(value)})"
        if isinstance(value, str):
            assert not _NUMBER.fullmatch(value), f"{what}{path}: {value!r} is a number written as text"
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            numbers += 1
    return numbers


def _safe_load(path):
    data = path.read_bytes()
    data.decode("utf-8")  # valid UTF-8, or UnicodeDecodeError
    return yaml.safe_load(data)


@pytest.fixture(scope="module")
def unit(tmp_path_factory, run_imufit, fixtures):
    """A real fitted calibration with the noise block of `imufit allan` appended, and its files."""
    d = tmp_path_factory.mktemp("machine_text")
    (d / "static.yaml").write_text(
        "format: imufit-plan\nversion: 1\ngravity_mps2: 9.81\nsegments:\n  - {id: 1, up: [0, 0, 1]}\n"
    )
    run_imufit("simulate", "-p", d / "static.yaml", "-c", fixtures / "mems_truth.yaml", "-o", d / "static.csv",
               "--rate", "100", "--dwell", "60", "--temps", "25", "--gyro-noise-density", "1e-4",
               "--accel-noise-density", "1e-3", "--seed", "5", "-q")
    run_imufit("allan", "-s", d / "static.csv", "--calibration", fixtures / "mems_truth.yaml", "-o", d / "adev.csv",
               "--noise-yaml", d / "noise.yaml", "-q")
    fitted = (fixtures / "golden" / "mems_6pos_soak.yaml").read_text()
    (d / "unit.yaml").write_text(fitted + (d / "noise.yaml").read_text())
    return d


def test_the_noise_yaml_reads_as_numbers(unit):
    document = _safe_load(unit / "noise.yaml")
    assert _assert_typed(document, "noise.yaml") > 20
    noise = document["noise"]
    assert isinstance(noise["sample_count"], int)
    for name, column in noise["columns"].items():
        assert isinstance(column["fitted"], bool), name
        if column["fitted"]:
            assert isinstance(column["points_used"], int), name
            pairs = [v for v in column.values() if isinstance(v, list)]
            assert pairs and all(isinstance(x, (int, float)) for pair in pairs for x in pair), name
    for key, value in noise["kalibr"].items():
        assert isinstance(value, (int, float)) and value > 0, key


def test_a_fitted_calibration_with_noise_reads_as_numbers_and_exports_to_valid_json(unit, run_imufit):
    document = _safe_load(unit / "unit.yaml")
    assert _assert_typed(document, "unit.yaml") > 300
    assert isinstance(document["created_utc"], str)  # quoted: not a datetime
    fit = document["fit"]
    assert isinstance(fit["samples_read"], int) and isinstance(fit["g_sensitivity_fitted"], bool)
    assert all(isinstance(t, float) for t in fit["distinct_temperatures_c"])
    run_imufit("export", "-q", "-c", unit / "unit.yaml", "-f", "json", "-o", unit / "unit.json")
    exported = json.loads((unit / "unit.json").read_text(), parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    jsonschema.validate(exported, SCHEMA, cls=jsonschema.Draft202012Validator)
    del exported["export"]
    assert exported == document  # every value, of the same type, as PyYAML reads the YAML
    # The JSON is read wherever a calibration is: `imufit apply -c unit.json`.
    samples = ROOT / "fixtures" / "mems_6pos_noiseless.csv.gz"
    run_imufit("apply", "-q", "-c", unit / "unit.json", "-s", samples, "-o", unit / "applied.csv")


# A noise block written by hand, its figures as a person types them: 2e-06 is a number to yaml-cpp,
# and must be one to Kalibr (issue 30: Kalibr's noise check raised TypeError on '2e-06').
HAND_NOISE = """noise:
  format: imufit-noise
  version: 1
  kalibr:
    gyroscope_noise_density: 0.0002
    gyroscope_random_walk: 2e-06
    accelerometer_noise_density: 0.002
    accelerometer_random_walk: 3e-05
    update_rate: 100
"""


@pytest.mark.parametrize("noise", ["allan", "hand"])
def test_kalibr_imu_yaml_reads_as_numbers(unit, run_imufit, fixtures, noise):
    calibration = unit / "unit.yaml"
    if noise == "hand":
        calibration = unit / "hand.yaml"
        calibration.write_text((fixtures / "golden" / "mems_6pos_soak.yaml").read_text() + HAND_NOISE)
    run_imufit("export", "-q", "-c", calibration, "-f", "kalibr", "-o", unit / f"imu_{noise}.yaml",
               "--gyro-raw-per-radps", "939.65", "--accel-raw-per-mps2", "208.838", "--force")
    imu = _safe_load(unit / f"imu_{noise}.yaml")
    _assert_typed(imu, "imu.yaml")
    if noise == "hand":
        assert imu["gyroscope_random_walk"] == 2e-06 and imu["accelerometer_random_walk"] == 3e-05
    # What Kalibr's IccSensors reads, as floats it can compare and take the square root of.
    for key in ("accelerometer_noise_density", "accelerometer_random_walk", "gyroscope_noise_density",
                "gyroscope_random_walk", "update_rate"):
        assert isinstance(imu[key], (int, float)) and not isinstance(imu[key], bool), key
        assert math.isfinite(imu[key]) and imu[key] > 0, key
    for sensor, keys in (("accelerometers", ("M", "b")), ("gyroscopes", ("M", "A", "C_gyro_i", "b"))):
        for key in keys:
            flat = [x for row in imu[sensor][key] for x in (row if isinstance(row, list) else [row])]
            assert all(isinstance(x, (int, float)) for x in flat), (sensor, key)


def test_plan_design_and_plan_check_read_as_numbers(tmp_path, run_imufit, fixtures):
    schedule = ["--gyro-noise-density", "1e-4", "--accel-noise-density", "1e-3", "--dwell", "20",
                "--transition", "10", "--rate", "100", "--tolerance", "gyro.bias=0.0012,accel.bias=0.1,gyro.scale=60"]
    run_imufit("plan", "design", "-o", tmp_path / "designed.yaml", "--positions", "faces", "--rates", "100,300",
               "--latitude", "52.27", "--set-points=-40,-5.45,50.45,85", *schedule)
    plan = _safe_load(tmp_path / "designed.yaml")
    assert _assert_typed(plan, "designed.yaml") > 10
    assert all(isinstance(s["id"], int) for s in plan["segments"])
    checked = run_imufit("plan", "check", fixtures / "plan_24pos.yaml", "--temps=-40,-5.45,50.45,85",
                         "--format", "yaml", *schedule, check=False)
    assert checked.returncode in (0, 3), checked.stderr
    as_yaml = yaml.safe_load(checked.stdout)
    assert _assert_typed(as_yaml, "plan check") > 10
    as_json = run_imufit("plan", "check", fixtures / "plan_24pos.yaml", "--temps=-40,-5.45,50.45,85",
                         "--format", "json", *schedule, check=False)
    assert json.loads(as_json.stdout) == as_yaml


def test_a_latin1_file_name_leaves_the_outputs_utf8(unit, run_imufit, fixtures):
    """The byte is written as the code point of the same value (Latin-1's reading): é."""
    name = os.fsencode(unit) + b"/static_\xe9t\xe9.csv"
    with open(name, "wb") as f:
        f.write((unit / "static.csv").read_bytes())
    result = subprocess.run([os.fsencode(_binary()), b"allan", b"-s", name, b"--calibration",
                             os.fsencode(fixtures / "mems_truth.yaml"), b"-o", os.fsencode(unit / "latin1_adev.csv"),
                             b"--noise-yaml", os.fsencode(unit / "latin1_noise.yaml"), b"-q"], capture_output=True)
    assert result.returncode == 0, result.stderr
    document = _safe_load(unit / "latin1_noise.yaml")
    assert document["noise"]["samples"].endswith("static_\u00e9t\u00e9.csv")
