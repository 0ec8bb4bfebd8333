"""`imufit export --format json` against its JSON Schema (docs/calibration.schema.json).

The golden export of fixtures/golden/export and a fitted calibration's export (with its sigma and
fit blocks) must validate; the JSON must be plain JSON (no NaN or Infinity) and read back with the
same numbers as the calibration file.
"""

import json
import math

import pytest
import yaml

jsonschema = pytest.importorskip("jsonschema")

from conftest import ROOT  # noqa: E402

SCHEMA = json.loads((ROOT / "docs" / "calibration.schema.json").read_text())


def _strict_json(text):
    def refuse(constant):
        raise ValueError(f"{constant} is not JSON")

    return json.loads(text, parse_constant=refuse)


def test_schema_is_a_valid_schema():
    jsonschema.Draft202012Validator.check_schema(SCHEMA)


def test_golden_json_export_validates(fixtures):
    document = _strict_json((fixtures / "golden" / "export" / "mems_truth.json").read_text())
    jsonschema.validate(document, SCHEMA, cls=jsonschema.Draft202012Validator)


def test_a_fitted_calibration_exports_to_valid_json_with_the_same_numbers(fixtures, run_imufit, tmp_path):
    calibration = fixtures / "golden" / "mems_6pos_soak.yaml"
    out = tmp_path / "unit.json"
    run_imufit("export", "-q", "-c", calibration, "-f", "json", "-o", out)
    document = _strict_json(out.read_text())
    jsonschema.validate(document, SCHEMA, cls=jsonschema.Draft202012Validator)
    source = yaml.safe_load(calibration.read_text())
    for sensor in ("gyro", "accel"):
        for group, axes in source[sensor].items():
            if group == "unit":
                continue
            for axis, terms in axes.items():
                assert document[sensor][group][axis] == terms
                assert all(math.isfinite(t) for t in document[sensor][group][axis])
    assert "sigma" in document and "fit" in document
    assert document["export"]["calibration_file"] == "mems_6pos_soak.yaml"
