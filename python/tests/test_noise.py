"""allan() and noise_terms(): NIST SP 1065 reference values, the same numbers as `imufit allan`,
known-truth recovery, and the errors."""

import math

import numpy as np
import pytest
import yaml

import imufit

# Relative, worst case: the published deviations have 7 significant digits (as tests/noise_test.cc).
REFERENCE_TOLERANCE = 1e-6
# Relative, worst case: the same library calls as the command.
CLI_TOLERANCE = 1e-12
# Worst-case recovery of a simulated noise term, in its reported 1-sigma.
RECOVERY_SIGMAS = 4.0

# The NBS 9-point frequency data set (SP 1065 section 12.5, table 31).
NBS9 = [892, 809, 823, 798, 671, 644, 883, 903, 677]


def nbs1000():
    """The 1000-point test set of SP 1065 section 12.5: n(i+1) = 16807 n(i) mod (2^31 - 1)."""
    y, n = [], 1234567890
    for _ in range(1000):
        y.append(n / 2147483647.0)
        n = (16807 * n) % 2147483647
    return np.array(y)


# SP 1065 tables 32 (NBS9, tau = 1, 2) and 34 (1000 points, tau = 1, 10, 100).
REFERENCES = [
    (NBS9, [1, 2], {"adev": [91.22945, 115.8082], "oadev": [91.22945, 85.95287], "mdev": [91.22945, 74.78849],
                    "tdev": [52.67135, 86.35831], "hdev": [70.80608, 116.7980], "ohdev": [70.80607, 85.61487],
                    "totdev": [91.22945, 93.90379]}),
    (nbs1000(), [1, 10, 100], {
        "adev": [2.922319e-01, 9.965736e-02, 3.897804e-02], "oadev": [2.922319e-01, 9.159953e-02, 3.241343e-02],
        "mdev": [2.922319e-01, 6.172376e-02, 2.170921e-02], "tdev": [1.687202e-01, 3.563623e-01, 1.253382e+00],
        "hdev": [2.943883e-01, 1.052754e-01, 3.910860e-02], "ohdev": [2.943883e-01, 9.581083e-02, 3.237638e-02],
        "totdev": [2.922319e-01, 9.134743e-02, 3.406530e-02]}),
]


@pytest.mark.parametrize("data,taus,published", REFERENCES, ids=["nbs9", "nbs1000"])
def test_nist_sp1065_reference_values(data, taus, published):
    for estimator, devs in published.items():
        result = imufit.allan(data, 1.0, estimator=estimator, taus=taus)
        assert result.estimator == estimator
        assert result.tau_s.tolist() == [float(t) for t in taus]
        np.testing.assert_allclose(result.dev, devs, rtol=REFERENCE_TOLERANCE, err_msg=estimator)
    assert imufit.allan(data, 1.0, taus=taus).terms[0] == len(data) - 1  # oadev: N - 2m with N = n + 1


def white_and_walk(n, tau0_s, arw, rrw, seed):
    """Rates with white noise of density `arw` and a bias random walk of density `rrw`."""
    rng = np.random.default_rng(seed)
    white = rng.normal(0.0, arw / math.sqrt(tau0_s), n)
    walk = np.cumsum(rng.normal(0.0, rrw * math.sqrt(tau0_s), n))
    return white + walk


def test_allan_and_noise_terms_match_imufit_allan(tmp_path, run_imufit):
    tau0_s = 0.01
    y = white_and_walk(20000, tau0_s, 1e-3, 1e-4, seed=5)
    samples = tmp_path / "static.csv"
    with open(samples, "w") as file:
        file.write("time_s,gyro_x\n")
        for i, value in enumerate(y):
            file.write(f"{i * tau0_s!r},{value!r}\n")
    for estimator in ("oadev", "mdev", "totdev"):
        out = tmp_path / f"{estimator}.csv"
        run_imufit("allan", "--samples", samples, "-c", "gyro_x", "-e", estimator, "-o", out,
                   "--noise-yaml", tmp_path / f"{estimator}.yaml", "-q")
        rows = np.genfromtxt(out, delimiter=",", names=True, dtype=None, encoding="utf-8")
        result = imufit.allan(y, tau0_s, estimator=estimator)
        assert len(result) == len(rows)
        np.testing.assert_allclose(result.tau_s, rows["tau_s"], rtol=CLI_TOLERANCE)
        assert result.terms.tolist() == rows["terms"].tolist()
        for key in ("dev", "dev_lo", "dev_hi"):
            np.testing.assert_allclose(getattr(result, key), rows[key], rtol=CLI_TOLERANCE, err_msg=key)
        # The command fits the IEEE 952 terms to the oadev at the same taus, whatever the estimator.
        column = yaml.safe_load((tmp_path / f"{estimator}.yaml").read_text())["noise"]["columns"]["gyro_x"]
        terms = imufit.noise_terms(y, tau0_s)
        assert terms.fitted and column["fitted"]
        assert terms.points_used == column["points_used"]
        for name, key in (("random_walk", "random_walk_rad_per_sqrt_s"), ("bias_instability", "bias_instability_radps"),
                          ("rate_random_walk", "rate_random_walk_radps_per_sqrt_s")):
            value, sigma = column[key]
            assert terms.value[name] == pytest.approx(value, rel=CLI_TOLERANCE, abs=1e-300)
            assert terms.sigma[name] == pytest.approx(sigma, rel=CLI_TOLERANCE, abs=1e-300)
        # An oadev result fitted directly gives the same terms.
        direct = imufit.noise_terms(imufit.allan(y, tau0_s))
        assert direct.value == terms.value and direct.sigma == terms.sigma


def test_noise_terms_recover_simulated_arw_and_rrw():
    arw, rrw = 2e-3, 5e-5
    terms = imufit.noise_terms(white_and_walk(400000, 0.01, arw, rrw, seed=11), 0.01)
    assert terms.fitted
    assert abs(terms.arw - arw) < RECOVERY_SIGMAS * terms.arw_sigma, (terms.arw, terms.arw_sigma)
    assert abs(terms.rrw - rrw) < RECOVERY_SIGMAS * terms.rrw_sigma, (terms.rrw, terms.rrw_sigma)
    assert terms.arw_sigma < 0.05 * arw
    np.testing.assert_allclose(terms.model_deviation([1.0]), [math.sqrt(
        sum(terms.term_deviation(name, 1.0) ** 2 for name in terms.value))], rtol=1e-12)
    only_white = imufit.noise_terms(white_and_walk(400000, 0.01, arw, 0.0, seed=12), 0.01, terms=["random_walk"])
    assert only_white.free == {"quantization": False, "random_walk": True, "bias_instability": False,
                               "rate_random_walk": False, "rate_ramp": False}
    assert abs(only_white.arw - arw) < RECOVERY_SIGMAS * only_white.arw_sigma


def test_filtered_white_noise_is_detected_and_quoted():
    # White noise through a first-order low-pass (DC gain 1): the filter is detected, its taus left
    # out, and the fitted and quoted ARW hold the truth (issue 33).
    arw, tau0, a = 2e-3, 0.01, 0.45
    w = np.random.default_rng(21).normal(0.0, arw / math.sqrt(tau0), 200000)
    y = np.empty_like(w)
    y[0] = w[0]
    for i in range(1, len(w)):
        y[i] = a * y[i - 1] + (1.0 - a) * w[i]
    terms = imufit.noise_terms(y, tau0, taus="octave")
    assert terms.filter_detected and terms.filtered_points > 0
    assert terms.describes_curve
    assert terms.fit_taus_s[0] > tau0
    assert abs(terms.arw - arw) < RECOVERY_SIGMAS * terms.arw_sigma, (terms.arw, terms.arw_sigma)
    quote = terms.quote("random_walk")
    assert quote["interval"][0] <= arw <= quote["interval"][1], quote
    assert quote["from"].startswith("IEEE 952 fit")
    assert terms.quote("bias_instability")["interval"][0] == 0.0  # no phantom bias instability
    low, high = terms.readouts["random_walk_taus_s"]
    assert low >= terms.fit_taus_s[0] and high > low


def test_record_length_from_data_sheet_values():
    # ADIS16405 data sheet: ARW 2 deg/sqrt(h), in-run bias stability 25.2 deg/h.
    n = 2.0 * math.pi / 180 / 60
    b = 25.2 * math.pi / 180 / 3600
    quarter = imufit.record_length(n, b, 0.0, 0.01)
    tenth = imufit.record_length(n, b, 0.0, 0.01, precision=0.1)
    assert 0 < quarter["bias_instability_s"] < tenth["bias_instability_s"]
    assert math.isnan(quarter["rate_random_walk_s"])
    with pytest.raises(imufit.InputError):
        imufit.record_length(n, b, 0.0, 0.01, precision=1.5)


def test_bad_arguments_raise_input_error():
    y = np.zeros(100)
    with pytest.raises(imufit.InputError, match="estimator 'xdev'|estimator \"xdev\".*oadev"):
        imufit.allan(y, 1.0, estimator="xdev")
    with pytest.raises(imufit.InputError, match="taus"):
        imufit.allan(y, 1.0, taus="weekly")
    with pytest.raises(imufit.InputError):
        imufit.allan(y, 1.0, taus=[1.5])
    with pytest.raises(ValueError, match="tau0_s"):
        imufit.allan(y, 0.0)
    with pytest.raises(imufit.InputError, match=r"shape \(N,\)"):
        imufit.allan(np.zeros((10, 2)), 1.0)
    with pytest.raises(imufit.InputError, match="adev, oadev or totdev"):
        imufit.noise_terms(imufit.allan(nbs1000(), 1.0, estimator="mdev"))
    with pytest.raises(imufit.InputError, match="tau0_s"):
        imufit.noise_terms(y)
    with pytest.raises(imufit.InputError, match="not one of"):
        imufit.noise_terms(nbs1000(), 1.0, terms=["flicker"])
