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
