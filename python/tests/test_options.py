"""The keyword options of fit() and simulate(): the .pyi stub lists exactly the options of the
libraries' option tables, and a bad value is refused naming the option and its value."""

import ast
import pathlib

import numpy as np
import pytest

import imufit

STUB = pathlib.Path(__file__).resolve().parents[1] / "imufit" / "__init__.pyi"


def stub_keys(class_name):
    tree = ast.parse(STUB.read_text())
    for node in tree.body:
        if isinstance(node, ast.ClassDef) and node.name == class_name:
            return [item.target.id for item in node.body if isinstance(item, ast.AnnAssign)]
    raise AssertionError(f"{class_name} is not in {STUB}")


@pytest.mark.parametrize("class_name, described", [("_FitOptions", imufit.fit_options),
                                                   ("_FieldFitOptions", imufit.fit_field_options),
                                                   ("_SimulateOptions", imufit.simulate_options)])
def test_stub_lists_every_option_of_the_table(class_name, described):
    keys = stub_keys(class_name)
    assert len(keys) == len(set(keys)), keys
    assert keys == list(described()), "the stub and the option table disagree"


def test_every_option_has_a_description():
    for described in (imufit.fit_options(), imufit.fit_field_options(), imufit.simulate_options()):
        for key, (_, description) in described.items():
            assert description, key


def test_validation_names_the_option_and_its_value(fixtures):
    plan, samples = fixtures / "plan_6pos.yaml", fixtures / "mems_6pos_soak.csv.gz"
    with pytest.raises(imufit.InputError, match=r"loss_scale = -2: must be > 0"):
        imufit.fit(plan, samples, loss_scale=-2.0)
    with pytest.raises(imufit.InputError, match=r"turn_margin_s = -1: must be >= 0"):
        imufit.fit(plan, samples, turn_margin_s=-1.0)
    with pytest.raises(imufit.InputError, match=r"drop_burst = 0: must be >= 1"):
        imufit.simulate(plan, imufit.Calibration(), drop_burst=0)


def test_new_options_reach_the_fit(fixtures, tmp_path):
    # turn_margin_s and prior were missing from the keywords before the options had one table.
    assert imufit.fit_options()["turn_margin_s"][0] == 2.0
    assert imufit.fit_options()["prior"][0] == ""
    plan, samples = fixtures / "plan_6pos.yaml", fixtures / "mems_6pos_soak.csv.gz"
    prior = imufit.Calibration.load(fixtures / "mems_truth.yaml")
    prior.save(tmp_path / "prior.yaml")
    result = imufit.fit(plan, samples, fit="accel", prior=tmp_path / "prior.yaml")
    # The held gyro keeps the prior's values (through the fit's temperature basis and back).
    np.testing.assert_allclose(result.calibration.gyro["bias"], prior.gyro["bias"], rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(result.calibration.gyro["scale"], prior.gyro["scale"], rtol=1e-9)
    assert imufit.simulate_options()["ramp_c"][0] is None


def test_the_command_offers_the_table_options(fixtures, tmp_path, run_imufit):
    # Options the command line lacked before the options had one table.
    fit_help = run_imufit("fit", "--help").stdout
    for flag in ("--turn-margin", "--segment-noise-quantile", "--segment-threshold-factor", "--rank-tolerance",
                 "--threads", "--check-samples", "--prior", "--no-g-sensitivity"):
        assert flag in fit_help, flag
    batch_help = run_imufit("batch", "--help").stdout
    assert "--turn-margin" in batch_help and "--validate" in batch_help
    assert "--threads" not in batch_help and "--check-samples" not in batch_help
    bad = run_imufit("fit", "--plan", fixtures / "plan_6pos.yaml", "--samples", fixtures / "mems_6pos_soak.csv.gz",
                     "-o", tmp_path / "cal.yaml", "--turn-margin", "-1", check=False)
    assert bad.returncode == 2
    assert "turn_margin_s = -1: must be >= 0" in bad.stderr, bad.stderr


def stub_function_defaults(name):
    tree = ast.parse(STUB.read_text())
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name == name:
            args = node.args.args
            defaults = [None] * (len(args) - len(node.args.defaults)) + node.args.defaults
            return {a.arg: d for a, d in zip(args, defaults)}
    raise AssertionError(f"{name} is not in {STUB}")


@pytest.mark.parametrize("function, described", [("allan", imufit.allan_options),
                                                 ("noise_terms", imufit.noise_terms_options)])
def test_noise_functions_take_their_defaults_from_the_tables(function, described):
    # The defaults live in AllanOptions and NoiseFitOptions only: the stub says `...` for each
    # keyword of the table, and the module's signature shows the table's default.
    stub = stub_function_defaults(function)
    signature = getattr(imufit, function).__doc__.splitlines()[0]
    for key, (default, description) in described().items():
        assert description, key
        if key not in stub:
            continue  # not a keyword of this function (the noise fit's iterations)
        assert isinstance(stub[key], ast.Constant) and stub[key].value is Ellipsis, key
        assert f"{key}: {type(default).__name__} = {default!r}" in signature, (key, signature)


def test_allan_options_are_those_of_the_command(run_imufit):
    help_text = run_imufit("allan", "--help").stdout
    confidence = imufit.allan_options()["confidence"][0]
    assert 0.68 < confidence < 0.69  # one sigma
    assert f"--confidence FLOAT={confidence:g}" in help_text
    with pytest.raises(imufit.InputError, match=r"confidence = 1.5: must lie in \(0, 1\)"):
        imufit.allan(np.zeros(100), 0.01, confidence=1.5)
    with pytest.raises(imufit.InputError, match=r"min_clusters = 1: must be >= 2"):
        imufit.noise_terms(np.zeros(100), 0.01, min_clusters=1.0)
