"""A session by hand recorded as a ROS 1 bag, written by ROS's own Python `rosbag` writer.

A simulated hand session (`imufit simulate --field`, raw counts) is converted to SI units (rad/s,
m/s^2, as a ROS driver publishes sensor_msgs/Imu) and written twice: as a bag (sensor_msgs/Imu plus
sensor_msgs/Temperature at the same stamps) and as a samples CSV of the very same numbers.
`imufit fit --field` must give the same calibration from both, and, against the raw-count fit of the
original session, the same coefficients converted to SI: the field fit works on SI magnitudes
(noise floor, starting values, conditioning) as on counts.
"""

import csv
import hashlib
import math

import pytest
import yaml

rosbag = pytest.importorskip("rosbag")
rospy = pytest.importorskip("rospy")
sensor_msgs = pytest.importorskip("sensor_msgs.msg")

# fixtures/mems_truth.yaml: 16-bit counts, 939.65 LSB per rad/s and 208.838 LSB per m/s^2.
GYRO_LSB_PER_RADPS = 939.65
ACCEL_LSB_PER_MPS2 = 208.838
START_NS = 1_700_000_000 * 10**9  # a 2023 stamp, as a recording's

# The bag and the CSV hold the same doubles and the same solver runs on them: the calibrations are
# bit-identical (measured: 0). Absolute difference allowed per coefficient, share of its 1-sigma.
SAME_SAMPLES_TOLERANCE_SIGMA = 1e-9
# The SI fit against the count fit converted to SI: the same data in other units, so the same
# estimate up to the solver's convergence and rounding (measured 4e-7 sigma). Absolute difference,
# share of each coefficient's 1-sigma.
SI_VS_COUNTS_TOLERANCE_SIGMA = 1e-4
# Their sigmas, relative (measured 4e-10).
SI_VS_COUNTS_SIGMA_RELATIVE = 1e-6

# How each coefficient group converts from counts to SI: divided by this sensor scale (or not).
GROUP_DIVISOR = {
    ("gyro", "bias"): GYRO_LSB_PER_RADPS, ("gyro", "scale"): GYRO_LSB_PER_RADPS,
    ("gyro", "misalignment"): 1.0, ("gyro", "g_sensitivity"): GYRO_LSB_PER_RADPS,
    ("accel", "bias"): ACCEL_LSB_PER_MPS2, ("accel", "scale"): ACCEL_LSB_PER_MPS2,
    ("accel", "misalignment"): 1.0,
}


def simulate(run_imufit, fixtures, path, seed):
    run_imufit("simulate", "--field", "--calibration", fixtures / "mems_truth.yaml", "-o", path,
               "--poses", 12, "--dwell", 3, "--rate", 100, "--gyro-noise-density", 2e-4,
               "--accel-noise-density", 1e-3, "--quantize", "--time-jitter-s", 0.002,
               "--drop-probability", 0.002, "--warmup-c", 12, "--warmup-tau-s", 20, "--seed", seed)
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def write_si_bag_and_csv(rows, bag_path, csv_path, imu_topic="/imu/data", edit=None):
    """The session in SI units as a bag and as a CSV of the same doubles (times from the first
    stamp in whole nanoseconds, as imufit reads a bag)."""
    with rosbag.Bag(str(bag_path), "w") as bag, open(csv_path, "w") as out:
        out.write("time_s,temp_c,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n")
        first_ns = None
        for index, row in enumerate(rows):
            ns = START_NS + round(float(row["time_s"]) * 1e9)
            first_ns = ns if first_ns is None else first_ns
            stamp = rospy.Time(ns // 10**9, ns % 10**9)
            gyro = [float(row[k]) / GYRO_LSB_PER_RADPS for k in ("gyro_x", "gyro_y", "gyro_z")]
            accel = [float(row[k]) / ACCEL_LSB_PER_MPS2 for k in ("accel_x", "accel_y", "accel_z")]
            imu = sensor_msgs.Imu()
            imu.header.stamp = stamp
            imu.header.frame_id = "imu_link"
            imu.orientation_covariance[0] = -1  # no orientation estimate: fine, not read
            imu.angular_velocity.x, imu.angular_velocity.y, imu.angular_velocity.z = gyro
            imu.linear_acceleration.x, imu.linear_acceleration.y, imu.linear_acceleration.z = accel
            if edit:
                edit(index, imu)
            bag.write(imu_topic, imu, stamp)
            temperature = sensor_msgs.Temperature()
            temperature.header.stamp = stamp
            temperature.temperature = float(row["temp_c"])
            bag.write("/imu/temperature", temperature, stamp)
            values = [(ns - first_ns) * 1e-9, float(row["temp_c"]), *gyro, *accel]
            out.write(",".join(repr(v) for v in values) + "\n")


def coefficients(path):
    """Every coefficient of a calibration with its sigma: {(sensor, group, axis, term): (value, sigma)}."""
    document = yaml.safe_load(open(path))
    found = {}
    for sensor in ("gyro", "accel"):
        for group, axes in document[sensor].items():
            if group == "unit":
                continue
            for axis, terms in axes.items():
                for term, value in enumerate(terms):
                    sigma = document["sigma"][sensor][group][axis][term]
                    found[(sensor, group, str(axis), term)] = (value, sigma)
    return found, document


FIT = ("fit", "--field", "--bias-temp-order", 1, "-q")


def test_bag_fits_as_the_same_samples_from_csv_and_as_the_counts(run_imufit, fixtures, tmp_path):
    rows = simulate(run_imufit, fixtures, tmp_path / "counts.csv", seed=5)
    write_si_bag_and_csv(rows, tmp_path / "session.bag", tmp_path / "session_si.csv")
    run_imufit(*FIT, "--samples", tmp_path / "session.bag", "-o", tmp_path / "from_bag.yaml")
    run_imufit(*FIT, "--samples", tmp_path / "session_si.csv", "-o", tmp_path / "from_csv.yaml")
    run_imufit(*FIT, "--samples", tmp_path / "counts.csv", "-o", tmp_path / "from_counts.yaml")
    from_bag, bag_document = coefficients(tmp_path / "from_bag.yaml")
    from_csv, _ = coefficients(tmp_path / "from_csv.yaml")
    from_counts, _ = coefficients(tmp_path / "from_counts.yaml")
    assert len(from_bag) == len(from_csv) == len(from_counts) > 40

    # The bag is recorded as a CSV is: its name, its SHA-256 as on disk, the samples read.
    record = bag_document["fit"]
    assert record["samples_sha256"] == hashlib.sha256((tmp_path / "session.bag").read_bytes()).hexdigest()
    assert record["samples_read"] == len(rows)
    assert bag_document["fit_temp_range_c"][1] > bag_document["fit_temp_range_c"][0] + 1  # the warm-up, read

    fitted = 0
    for key, (value, sigma) in from_bag.items():
        csv_value, csv_sigma = from_csv[key]
        assert math.isfinite(value) and math.isfinite(sigma)
        assert abs(value - csv_value) <= SAME_SAMPLES_TOLERANCE_SIGMA * sigma + 1e-15 * abs(value), key
        assert abs(sigma - csv_sigma) <= SAME_SAMPLES_TOLERANCE_SIGMA * sigma + 1e-15, key
        if sigma == 0:
            continue  # held by the body frame, or a term not fitted
        fitted += 1
        counts_value, counts_sigma = from_counts[key]
        divisor = GROUP_DIVISOR[key[:2]]
        assert abs(value - counts_value / divisor) <= SI_VS_COUNTS_TOLERANCE_SIGMA * sigma, (
            key, value, counts_value / divisor, sigma)
        assert sigma == pytest.approx(counts_sigma / divisor, rel=SI_VS_COUNTS_SIGMA_RELATIVE), key
    assert fitted >= 30


def test_bad_bag_is_refused_with_one_located_line_and_exit_2(run_imufit, fixtures, tmp_path):
    rows = simulate(run_imufit, fixtures, tmp_path / "counts.csv", seed=6)[:400]

    def nan_at_message_123(index, imu):
        if index == 122:
            imu.angular_velocity.x = float("nan")

    bag = tmp_path / "nan.bag"
    write_si_bag_and_csv(rows, bag, tmp_path / "nan.csv", edit=nan_at_message_123)
    out = tmp_path / "cal.yaml"
    result = run_imufit("fit", "--field", "--samples", bag, "-o", out, check=False)
    assert result.returncode == 2
    assert result.stderr == (f'imufit: {bag}: topic "/imu/data", message 123: angular_velocity.x: nan is not a '
                             "finite number\n")
    assert not out.exists()

    # A topic that is not there: the bag's topics listed.
    result = run_imufit("fit", "--field", "--samples", tmp_path / "nan.bag", "--topic", "/imu", "-o", out,
                        check=False)
    assert result.returncode == 2
    assert result.stderr == (f'imufit: {bag}: --topic "/imu": no such topic in the bag; its topics: '
                             '"/imu/data" (sensor_msgs/Imu), "/imu/temperature" (sensor_msgs/Temperature)\n')

    # A bag cut short, as a recorder killed mid-session leaves it.
    cut = tmp_path / "cut.bag"
    cut.write_bytes(bag.read_bytes()[: bag.stat().st_size // 2])
    result = run_imufit("fit", "--field", "--samples", cut, "-o", out, check=False)
    assert result.returncode == 2
    assert result.stderr.startswith(f"imufit: {cut}: not a readable ROS bag")
    assert "rosbag reindex" in result.stderr
    assert result.stderr.count("\n") == 1
    assert not out.exists()
