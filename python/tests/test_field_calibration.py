"""A calibration by hand (`imufit fit --field`) read by its consumers' own readers.

Its typed `fit: field:` block and `body_frame` key load with PyYAML as numbers and names, the JSON
export validates against docs/calibration.schema.json with the same values, and the module reads
them as attributes (FieldRecord, Calibration.body_frame).
"""

import json

import pytest
import yaml

jsonschema = pytest.importorskip("jsonschema")

import imufit  # noqa: E402
from conftest import ROOT  # noqa: E402

SCHEMA = json.loads((ROOT / "docs" / "calibration.schema.json").read_text())
FIELD_KEYS = {
    "poses": int, "turns": int, "gravity_mps2": float, "accel_norm_rms_mps2": float,
    "gyro_static_rms_radps": float, "gravity_direction_rms_rad": float, "reduced_chi2": float,
    "noise_scale_accel_rests": (int, float), "noise_scale_gyro_rests": (int, float),
    "noise_scale_turns": (int, float), "saturated_turns": int, "gravity_source": str,
}


def test_field_calibration_yaml_json_and_module_agree(fixtures, run_imufit, tmp_path):
    calibration = fixtures / "golden" / "mems_field_session.yaml"
    source = yaml.safe_load(calibration.read_text())
    assert source["body_frame"] == "accelerometer_xy"
    field = source["fit"]["field"]
    assert set(field) == set(FIELD_KEYS)
    for key, kind in FIELD_KEYS.items():
        assert isinstance(field[key], kind) and not isinstance(field[key], bool), (key, field[key])

    out = tmp_path / "field.json"
    run_imufit("export", "-q", "-c", calibration, "-f", "json", "-o", out)
    document = json.loads(out.read_text())
    jsonschema.validate(document, SCHEMA, cls=jsonschema.Draft202012Validator)
    assert document["body_frame"] == "accelerometer_xy"
    assert document["fit"]["field"] == field

    bad = dict(document, body_frame="table")
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, SCHEMA, cls=jsonschema.Draft202012Validator)

    loaded = imufit.Calibration.load(calibration)
    assert loaded.body_frame == "accelerometer_xy"
    assert loaded.fit.field.poses == field["poses"]
    assert loaded.fit.field.accel_norm_rms_mps2 == field["accel_norm_rms_mps2"]
    assert imufit.Calibration.load(fixtures / "golden" / "mems_6pos_soak.yaml").body_frame is None


SESSION_LISTS = {
    "session_samples": str, "session_samples_sha256": str, "session_samples_read": int,
    "session_poses": int, "session_turns": int, "session_temp_min_c": (int, float),
    "session_temp_max_c": (int, float), "session_gyro_bias_chi2": float, "session_accel_bias_chi2": float,
}


def test_several_sessions_record_read_by_pyyaml_the_schema_and_the_module(fixtures, run_imufit, tmp_path):
    """Four sessions fitted jointly: the `fit: field:` block's session lists load with PyYAML as
    lists of one item per session (the SHA-256s as the files' own), the JSON export validates
    against the schema with the same lists, and the module reads them as attributes."""
    import hashlib

    sessions = []
    for temp_c in (0, 15, 30, 45):
        path = tmp_path / f"s{temp_c}.csv"
        run_imufit("simulate", "--field", "--calibration", fixtures / "mems_truth.yaml", "-o", path,
                   "--temps", temp_c, "--poses", 10, "--dwell", 3, "--rate", 50, "--gyro-noise-density", "2e-4",
                   "--accel-noise-density", "1e-3", "--serial", "SN0001", "--seed", 40 + temp_c, "-q")
        sessions.append(path)
    calibration = tmp_path / "joint.yaml"
    args = ["fit", "--field", "-q", "--bias-temp-order", 2, "--scale-temp-order", 1, "-o", calibration]
    for path in sessions:
        args += ["--samples", path]
    run_imufit(*args)
    source = yaml.safe_load(calibration.read_text())
    record = source["fit"]
    assert "samples" not in record and "samples_sha256" not in record
    field = record["field"]
    for key, kind in SESSION_LISTS.items():
        assert isinstance(field[key], list) and len(field[key]) == 4, key
        assert all(isinstance(item, kind) and not isinstance(item, bool) for item in field[key]), (key, field[key])
    assert field["session_samples"] == [str(path) for path in sessions]
    assert field["session_samples_sha256"] == [hashlib.sha256(path.read_bytes()).hexdigest() for path in sessions]
    assert sum(field["session_samples_read"]) == record["samples_read"]
    assert field["session_poses"] == [10, 10, 10, 10] and field["session_biases_tested"] is True

    out = tmp_path / "joint.json"
    run_imufit("export", "-q", "-c", calibration, "-f", "json", "-o", out)
    document = json.loads(out.read_text())
    jsonschema.validate(document, SCHEMA, cls=jsonschema.Draft202012Validator)
    assert document["fit"]["field"] == field
    bad = json.loads(out.read_text())
    bad["fit"]["field"]["session_samples_sha256"][0] = "not a digest"
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, SCHEMA, cls=jsonschema.Draft202012Validator)

    loaded = imufit.Calibration.load(calibration).fit.field
    assert loaded.session_samples == field["session_samples"]
    assert loaded.session_poses == field["session_poses"]
    assert loaded.session_gyro_bias_chi2 == field["session_gyro_bias_chi2"]
    assert loaded.session_biases_tested is True
    # A one-session file has none of the session keys.
    assert imufit.Calibration.load(fixtures / "golden" / "mems_field_session.yaml").fit.field.session_samples is None
