"""plan_check() and plan_design(): the command's tables as arrays, the keywords from the option
tables, and the same prediction as `imufit plan check`."""

import ast
import json
import pathlib

import numpy as np
import pytest

import imufit

STUB = pathlib.Path(__file__).resolve().parents[1] / "imufit" / "__init__.pyi"
NOISE = dict(gyro_noise_density=1e-4, accel_noise_density=1e-3, soak_temps_c=[-20, 10, 50, 85],
             dwell_s=20.0, rate_hz=100.0)


def stub_keys(class_name):
    for node in ast.parse(STUB.read_text()).body:
        if isinstance(node, ast.ClassDef) and node.name == class_name:
            keys = [item.target.id for item in node.body if isinstance(item, ast.AnnAssign)]
            bases = [b.id for b in node.bases if isinstance(b, ast.Name) and b.id.startswith("_Plan")]
            return sum((stub_keys(b) for b in bases), []) + keys
    raise AssertionError(class_name)


@pytest.mark.parametrize("class_name, described", [("_PlanCheckOptions", imufit.plan_check_options),
                                                   ("_PlanDesignOptions", imufit.plan_design_options)])
def test_stub_lists_every_option_of_the_table(class_name, described):
    assert stub_keys(class_name) == list(described())


def test_plan_check_returns_the_commands_table_as_arrays(fixtures, run_imufit):
    plan = fixtures / "plan_24pos.yaml"
    check = imufit.plan_check(plan, tolerance={"gyro.bias": 0.01}, **NOISE)
    rows = check["rows"]
    assert isinstance(rows["sigma"], np.ndarray) and rows["sigma"].shape == (len(rows["name"]),)
    assert check["limiting"] == rows["name"][0] and check["limiting"].startswith("gyro bias")
    assert np.all(rows["sigma"] > 0) and not check["tolerance_unmet"]
    # The command says the same, number for number.
    printed = run_imufit("plan", "check", plan, "--gyro-noise-density", "1e-4", "--accel-noise-density", "1e-3",
                         "--temps=-20,10,50,85", "--dwell", "20", "--rate", "100", "--tolerance", "gyro.bias=0.01",
                         "--format", "json")
    command = json.loads(printed.stdout)
    assert [r["name"] for r in command["rows"]] == rows["name"]
    np.testing.assert_allclose([r["sigma"] for r in command["rows"]], rows["sigma"], rtol=1e-8)


def test_plan_check_refuses_bad_keywords(fixtures):
    with pytest.raises(imufit.InputError, match="latitude_deg = 91"):
        imufit.plan_check(fixtures / "plan_24pos.yaml", latitude_deg=91.0, **NOISE)
    with pytest.raises(imufit.InputError, match="gyro.bogus"):
        imufit.plan_check(fixtures / "plan_24pos.yaml", tolerance={"gyro.bogus": 1.0}, **NOISE)
    with pytest.raises(imufit.InputError, match="white noise"):
        imufit.plan_check(fixtures / "plan_24pos.yaml")


def test_plan_design_meets_its_tolerances(tmp_path):
    tolerance = {"gyro.bias": 0.005, "accel.bias": 0.5}
    schedule = dict(gyro_noise_density=1e-4, accel_noise_density=1e-3, dwell_s=20.0, transition_s=10.0)
    design = imufit.plan_design(tolerance=tolerance, latitude_deg=52.27, set_points_c=[-40, 0, 40, 85],
                                **schedule)
    assert design["met"] and design["segment_count"] > 0
    assert design["hours"] <= design["greedy_hours"] + 1e-9
    assert np.all(design["check"]["rows"]["ratio"] <= 1.0)
    plan = tmp_path / "designed.yaml"
    plan.write_text(design["plan_yaml"])
    check = imufit.plan_check(plan, tolerance=tolerance, soak_temps_c=list(design["soaks_c"]), **schedule)
    assert not check["tolerance_unmet"]
