"""PX4 ULog sessions (`imufit fit --field --samples X.ulg`, docs/field.md "Sessions in a PX4 ULog").

The ULog files are written by ulog_writer.py, from PX4's format specification with struct.pack,
independently of imufit's C++ reader. A simulated hand session in SI units (raw = rad/s and m/s^2,
fixtures/px4_si_truth.yaml) written as a ULog with the gyro at twice the accelerometer's rate, amid
every other documented message type, fits to the coefficients of the same samples read as CSV; bad
logs are refused with one located line and exit status 2.
"""

import csv
import hashlib
import struct

import pytest
import yaml

import ulog_writer
from ulog_writer import SENSOR_FIELDS, ULogWriter, sensor_payload

# The ULog holds the accelerometer at every other gyro time. Its fit must equal, within this
# fraction of each coefficient's 1-sigma (measured: 0), the fit of a CSV of the same samples made
# here independently: float32 values, microsecond times, the accelerometer interpolated linearly
# at the gyro's times.
MAX_INTERPOLATED_DIFFERENCE_SIGMAS = 1e-3
# Against the simulated CSV, which has an accelerometer reading at every sample, the ULog has half
# of them: its fit differs by the noise of the other half, about one sigma (measured: RMS 0.50,
# worst 1.81 sigma). Bounds that a reader error (a wrong axis, unit, time or temperature) breaks.
MAX_HALF_RATE_RMS_SIGMAS = 1.0
MAX_HALF_RATE_SIGMAS = 3.5
BOOT_US = 5_000_000  # the log's time of the session's first sample, us


def _float32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def _interpolated_csv(rows, path):
    """The samples a ULog reader should make of write_session(rows, accel_every=2): the gyro's rows,
    the accelerometer interpolated linearly in time between its messages (every other row)."""
    times = [BOOT_US + int(round(r["time_s"] * 1e6)) for r in rows]
    accel = [(times[i], [_float32(rows[i]["accel_" + a]) for a in "xyz"]) for i in range(0, len(rows), 2)]
    lines = ["time_s,temp_c,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z"]
    j = 0
    for t, row in zip(times, rows):
        if t > accel[-1][0]:
            continue
        while j + 1 < len(accel) and accel[j + 1][0] < t:
            j += 1
        k = min(j + 1, len(accel) - 1)
        span = accel[k][0] - accel[j][0]
        w = (t - accel[j][0]) / span if span else 0.0
        values = [t * 1e-6, _float32(row["temp_c"])] + [_float32(row["gyro_" + a]) for a in "xyz"]
        values += [(1 - w) * accel[j][1][c] + w * accel[k][1][c] for c in range(3)]
        lines.append(",".join(repr(v) for v in values))
    path.write_text("\n".join(lines) + "\n")
    return path


def _rows(path):
    with open(path, newline="") as f:
        lines = [line for line in f if not line.startswith("#")]
    return [{k: float(v) for k, v in row.items() if v != ""} for row in csv.DictReader(lines)]


@pytest.fixture(scope="module")
def session(fixtures, run_imufit, tmp_path_factory):
    """A simulated hand session in SI: its CSV, and its ULog (gyro 200 Hz, accelerometer 100 Hz)."""
    folder = tmp_path_factory.mktemp("ulog")
    truth = fixtures / "px4_si_truth.yaml"  # mems_truth.yaml with its raw outputs in SI
    hand = folder / "hand.csv"
    run_imufit("simulate", "--field", "--calibration", truth, "-o", hand, "--poses", "12", "--dwell", "4",
               "--rate", "200", "--gyro-noise-density", "2e-4", "--accel-noise-density", "1e-3",
               "--time-jitter-s", "0.0005", "--drop-probability", "0.002", "--seed", "3")
    rows = _rows(hand)
    ulog = folder / "hand.ulg"
    ulog_writer.write_session(ulog, rows, gyro_every=1, accel_every=2, boot_us=BOOT_US)
    return folder, hand, ulog, rows


def _coefficients(calibration):
    values = {}
    for sensor in ("gyro", "accel"):
        for group, axes in calibration[sensor].items():
            if not isinstance(axes, dict):
                continue
            for axis, terms in axes.items():
                sigma = calibration["sigma"][sensor][group][axis][0]
                values[(sensor, group, axis)] = (terms[0], sigma)
    return values


def _differences(a, b):
    """Each coefficient's |a - b| / a's sigma (those the body frame holds, sigma 0, must be equal)."""
    assert a.keys() == b.keys() and len(a) >= 30
    z = {}
    for key, (value, sigma) in a.items():
        if sigma == 0:
            assert b[key][0] == pytest.approx(value, abs=1e-12), key
        else:
            z[key] = abs(b[key][0] - value) / sigma
    return z


def test_ulog_session_fits_as_its_csv(session, run_imufit):
    folder, hand, ulog, rows = session
    result = run_imufit("fit", "--field", "--samples", ulog, "-o", folder / "ulog_cal.yaml")
    assert "1 logging dropouts" in result.stderr, result.stderr
    from_ulog = yaml.safe_load((folder / "ulog_cal.yaml").read_text())
    assert from_ulog["fit"]["samples_sha256"] == hashlib.sha256(ulog.read_bytes()).hexdigest()
    # Every gyro message is a sample but those after the accelerometer's last message.
    assert len(rows) - 1 <= from_ulog["fit"]["samples_read"] <= len(rows)
    ulog_fit = _coefficients(from_ulog)

    same = _interpolated_csv(rows, folder / "interpolated.csv")
    run_imufit("fit", "--field", "--samples", same, "-o", folder / "interpolated_cal.yaml")
    z = _differences(_coefficients(yaml.safe_load((folder / "interpolated_cal.yaml").read_text())), ulog_fit)
    assert max(z.values()) <= MAX_INTERPOLATED_DIFFERENCE_SIGMAS, max(z.items(), key=lambda kv: kv[1])

    run_imufit("fit", "--field", "--samples", hand, "-o", folder / "csv_cal.yaml")
    z = _differences(_coefficients(yaml.safe_load((folder / "csv_cal.yaml").read_text())), ulog_fit)
    rms = (sum(v * v for v in z.values()) / len(z)) ** 0.5
    assert rms <= MAX_HALF_RATE_RMS_SIGMAS and max(z.values()) <= MAX_HALF_RATE_SIGMAS, (rms, max(z.values()))


def _small_log(path, rows=40, mutate=None, instances=(0,)):
    """A short session (too short to fit, long enough to read) with `mutate(writer, ids)` applied
    after the subscriptions."""
    w = ULogWriter(start_us=1000)
    w.flag_bits()
    w.format("sensor_accel:" + SENSOR_FIELDS)
    w.format("sensor_gyro:" + SENSOR_FIELDS)
    for instance in instances:
        w.subscribe(instance, 2 * instance, "sensor_gyro")
        w.subscribe(instance, 2 * instance + 1, "sensor_accel")
    if mutate:
        mutate(w)
    for i in range(rows):
        t = 10_000 + 5000 * i
        for instance in instances:
            w.data(2 * instance, sensor_payload(t, t, 0x2000 + instance, (0.01, 0.02, 0.03), 30.0))
            w.data(2 * instance + 1, sensor_payload(t, t, 0x1000 + instance, (0.1, 0.2, 9.8), 30.0))
    path.write_bytes(w.bytes())
    return path


def _refused(run_imufit, path, *extra):
    result = run_imufit("fit", "--field", "--samples", path, "-o", path.with_suffix(".yaml"), *extra, check=False)
    assert result.returncode == 2, (result.returncode, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(f"imufit: {path}: "), lines[0]
    assert not path.with_suffix(".yaml").exists()
    return lines[0]


def test_bad_ulogs_are_refused_with_a_located_line(run_imufit, tmp_path):
    def case(name, mutate=None, **kw):
        return _refused(run_imufit, _small_log(tmp_path / f"{name}.ulg", mutate=mutate, **kw))

    bad_magic = tmp_path / "bad_magic.ulg"
    bad_magic.write_bytes(b"ULog\x01\x12\x36" + bytes(9))
    line = _refused(run_imufit, bad_magic)
    assert "byte 0: not a ULog file" in line, line

    line = case("cut_short", lambda w: w.message("A", b"\x00\x09"))
    assert "'A'" in line and "cut short" in line and "byte " in line, line

    line = case("unknown_type", lambda w: w.format("bad_topic:uint64_t timestamp;no_such_type[2] thing;"))
    assert "'F' bad_topic" in line and "no_such_type" in line, line

    line = case("unknown_id", lambda w: w.data(99, struct.pack("<Q", 5)))
    assert "'D'" in line and "msg_id 99" in line, line

    def backwards(w):
        w.data(0, sensor_payload(10_000, 10_000, 0x2000, (0, 0, 0), 30.0))
        w.data(0, sensor_payload(9_000, 9_000, 0x2000, (0, 0, 0), 30.0))
    line = case("backwards", backwards)
    assert "'D' sensor_gyro[0]" in line and "timestamp_sample 9000 us goes back" in line, line

    line = case("nan", lambda w: w.data(1, sensor_payload(1, 1, 0x1000, (0, float("nan"), 9.8), 30.0)))
    assert "'D' sensor_accel[0]: y is nan" in line, line

    def no_gyro(path):
        w = ULogWriter()
        w.flag_bits()
        w.format("sensor_accel:" + SENSOR_FIELDS)
        w.format("sensor_combined:uint64_t timestamp;float[3] gyro_rad;")
        w.subscribe(0, 0, "sensor_accel")
        w.subscribe(0, 1, "sensor_combined")
        path.write_bytes(w.bytes())
        return path
    line = _refused(run_imufit, no_gyro(tmp_path / "no_gyro.ulg"))
    assert "no sensor_gyro topic (the log has: sensor_accel, sensor_combined)" in line, line

    line = _refused(run_imufit, _small_log(tmp_path / "instances.ulg", instances=(0, 1)))
    assert "several IMU instances" in line and "0x2001" in line and "--instance" in line, line
    line = _refused(run_imufit, tmp_path / "instances.ulg", "--instance", "3")
    assert "--instance 3" in line and "1 (device id 0x1001" in line, line


def test_unknown_incompat_bits_are_refused(run_imufit, tmp_path):
    w = ULogWriter()
    w.flag_bits(incompat=0x02)
    path = tmp_path / "incompat.ulg"
    path.write_bytes(w.bytes())
    line = _refused(run_imufit, path)
    assert "byte 16: 'B'" in line and "incompat_flags[0]" in line, line
