"""A PX4 ULog writer for the tests, written from PX4's "ULog File Format" specification
(docs.px4.io, dev_log/ulog_file_format) with struct.pack alone, independently of imufit's C++
reader (io/src/ulog_samples.cc), so that the reader is not tested against its own mirror.

Every message is {uint16 msg_size, uint8 msg_type, payload}, little endian, after the 16-byte
header "ULog" 01 12 35, version, uint64 start time in microseconds.
"""

import struct

MAGIC = b"ULog\x01\x12\x35"
SYNC_MAGIC = bytes([0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12])

# PX4's sensor_accel and sensor_gyro as PX4 v1.14 logs them (msg/SensorAccel.msg,
# msg/SensorGyro.msg): 44 bytes of fields, padded to 48; the trailing padding is not logged.
SENSOR_FIELDS = ("uint64_t timestamp;uint64_t timestamp_sample;uint32_t device_id;float x;float y;float z;"
                 "float temperature;uint32_t error_count;uint8_t[3] clip_counter;uint8_t samples;"
                 "uint8_t[4] _padding0;")


def sensor_payload(timestamp_us, timestamp_sample_us, device_id, xyz, temperature):
    """The data of one sensor_accel or sensor_gyro message (without its trailing padding)."""
    return struct.pack("<QQI4fI3BB", timestamp_us, timestamp_sample_us, device_id, *xyz, temperature, 0, 0, 0, 0, 1)


class ULogWriter:
    def __init__(self, start_us=0, version=1):
        self.out = bytearray(MAGIC + bytes([version]) + struct.pack("<Q", start_us))

    def message(self, msg_type, payload):
        self.out += struct.pack("<HB", len(payload), ord(msg_type)) + payload
        return self

    def flag_bits(self, compat=0, incompat=0, appended=(0, 0, 0), extra=b""):
        """'B': must be the first message. `extra`: bytes a future version may append."""
        payload = bytes([compat]) + bytes(7) + bytes([incompat & 0xFF]) + bytes([(incompat >> 8) & 0xFF]) + bytes(6)
        payload += struct.pack("<3Q", *appended) + extra
        return self.message("B", payload)

    def format(self, text):
        return self.message("F", text.encode())

    def info(self, key, value):
        """'I': key is "type name", e.g. "char[3] sys_name"."""
        key = key.encode()
        return self.message("I", bytes([len(key)]) + key + value)

    def multi_info(self, key, value, continued=False):
        key = key.encode()
        return self.message("M", bytes([1 if continued else 0, len(key)]) + key + value)

    def parameter(self, key, value):
        key = key.encode()
        return self.message("P", bytes([len(key)]) + key + value)

    def default_parameter(self, key, value, default_types=1):
        key = key.encode()
        return self.message("Q", bytes([default_types, len(key)]) + key + value)

    def subscribe(self, multi_id, msg_id, name):
        return self.message("A", struct.pack("<BH", multi_id, msg_id) + name.encode())

    def unsubscribe(self, msg_id):
        return self.message("R", struct.pack("<H", msg_id))

    def data(self, msg_id, payload):
        return self.message("D", struct.pack("<H", msg_id) + payload)

    def logging(self, level, timestamp_us, text):
        return self.message("L", struct.pack("<BQ", level, timestamp_us) + text.encode())

    def tagged_logging(self, level, tag, timestamp_us, text):
        return self.message("C", struct.pack("<BHQ", level, tag, timestamp_us) + text.encode())

    def sync(self):
        return self.message("S", SYNC_MAGIC)

    def dropout(self, duration_ms):
        return self.message("O", struct.pack("<H", duration_ms))

    def bytes(self):
        return bytes(self.out)


def write_session(path, rows, gyro_every=1, accel_every=2, boot_us=5_000_000, extras=True, instances=(0,)):
    """Writes samples `rows` (dicts of time_s, temp_c, gyro_x..z, accel_x..z, in SI) as a ULog:
    sensor_gyro at every `gyro_every`-th row, sensor_accel at every `accel_every`-th, each with its
    temperature, for each multi_id of `instances` (device ids 0x1000 + id and 0x2000 + id). With
    `extras`, the log holds every other documented message type too: nested and padded formats,
    information, multi information, parameters, logged strings, sync, dropouts, an unsubscribed
    topic, and a message type the specification does not define."""
    w = ULogWriter(start_us=boot_us)
    w.flag_bits(compat=1 if extras else 0)
    w.format("sensor_accel:" + SENSOR_FIELDS)
    w.format("sensor_gyro:" + SENSOR_FIELDS)
    if extras:
        # A nested type used before it is defined, an array of it, and padding.
        w.format("vehicle_status:uint64_t timestamp;esc_report[2] esc;uint8_t arming_state;uint8_t[7] _padding0;")
        w.format("esc_report:uint32_t esc_rpm;float[3] esc_current;int16_t temp;uint8_t[2] _padding0;")
        w.info("char[3] sys_name", b"PX4")
        w.info("char[9] ver_hw", b"PX4_FMU_6")
        w.info("uint32_t ver_sw_release", struct.pack("<I", 0x010E00FF))
        w.multi_info("char[5] perf_counter", b"first")
        w.multi_info("char[6] perf_counter", b"second", continued=True)
        w.parameter("int32_t SDLOG_PROFILE", struct.pack("<i", 1 << 2))
        w.parameter("float IMU_GYRO_CUTOFF", struct.pack("<f", 40.0))
        w.default_parameter("int32_t SDLOG_PROFILE", struct.pack("<i", 1), default_types=3)
        w.subscribe(0, 0, "vehicle_status")
    first_id = 1 if extras else 0
    ids = {}
    for k, instance in enumerate(instances):
        ids[("gyro", instance)] = first_id + 2 * k
        ids[("accel", instance)] = first_id + 2 * k + 1
        w.subscribe(instance, ids[("gyro", instance)], "sensor_gyro")
        w.subscribe(instance, ids[("accel", instance)], "sensor_accel")
    if extras:
        w.logging(ord("6"), boot_us, "[logger] started")
    for i, row in enumerate(rows):
        t_us = boot_us + int(round(row["time_s"] * 1e6))
        for instance in instances:
            if i % gyro_every == 0:
                w.data(ids[("gyro", instance)],
                       sensor_payload(t_us + 150, t_us, 0x2000 + instance,
                                      (row["gyro_x"], row["gyro_y"], row["gyro_z"]), row["temp_c"]))
            if i % accel_every == 0:
                w.data(ids[("accel", instance)],
                       sensor_payload(t_us + 150, t_us, 0x1000 + instance,
                                      (row["accel_x"], row["accel_y"], row["accel_z"]), row["temp_c"]))
        if extras and i % 500 == 250:
            esc = struct.pack("<I3fh2x", 12000, 1.0, 1.5, 2.0, 41)
            w.data(0, struct.pack("<Q", t_us) + esc + esc + bytes([2]))  # trailing padding left out
            w.tagged_logging(ord("4"), 3, t_us, "tagged message")
            w.sync()
            w.message("Z", b"a message type the specification does not define")
            w.parameter("float IMU_GYRO_CUTOFF", struct.pack("<f", 30.0))
        if extras and i == len(rows) // 2:
            w.dropout(0)  # noted, nothing lost here
    if extras:
        w.unsubscribe(0)
    with open(path, "wb") as out:
        out.write(w.bytes())


def main():
    """python3 ulog_writer.py SAMPLES.csv OUT.ulg: a samples CSV (SI values) as a PX4 ULog, the gyro
    at every row and the accelerometer at every other (docs/field.md, "Sessions in a PX4 ULog")."""
    import csv
    import sys

    if len(sys.argv) != 3:
        sys.exit(main.__doc__)
    with open(sys.argv[1], newline="") as f:
        rows = [{k: float(v) for k, v in row.items() if v not in ("", None)}
                for row in csv.DictReader(line for line in f if not line.startswith("#"))]
    write_session(sys.argv[2], rows)


if __name__ == "__main__":
    main()
