/* imufit — the correction model for firmware: C99, no allocation, no I/O, nothing from libc.
 *
 * Evaluates exactly the model `imufit apply` evaluates (docs/spec.md section 1,
 * model/include/imufit/model/sensor_model.h), the accelerometer first, then the gyro with the
 * corrected specific force of the same sample:
 *
 *   a_hat     = M_a * diag(1/S_a) * (A - V_a)                  [m/s^2]
 *   omega_hat = M_g * diag(1/S_g) * (B - V_g - H * a_hat)      [rad/s]
 *
 * B, A raw gyro / accelerometer output (the unit's own numbers); V bias (raw); S scale factor
 * (raw per SI unit); M misalignment (unit diagonal, maps the sensor frame into the body frame);
 * H gyro g-sensitivity (raw per m/s^2). Every coefficient is a cubic in dT = T - T_ref, evaluated
 * by Horner: C = c0 + dT (c1 + dT (c2 + dT c3)).
 *
 * Temperature: T is clamped to the calibration's fitted range [temp_min_c, temp_max_c] before dT
 * is formed, so the cubics are never extrapolated (a NaN temperature counts as below the range);
 * imufit_correct() then returns IMUFIT_TEMP_CLAMPED. This differs from `imufit apply`, which
 * evaluates the cubics at any temperature, warns about samples beyond the fitted range, and
 * refuses a correction that is not a finite number (io/include/imufit/pipeline/correct_file.h). Inside
 * the range the two agree (docs/export.md: within 1e-12 relative in the double build, within the
 * derived float32 bound in the float build).
 *
 * Coefficient layout, as in the calibration file: row i of `gyro` / `accel` holds c0..c3 of
 *
 *   i      gyro (21 rows)                              accel (12 rows)
 *   0..2   bias x, y, z                                bias x, y, z
 *   3..5   scale x, y, z                               scale x, y, z
 *   6..11  misalignment xy xz yx yz zx zy              misalignment xy xz yx yz zx zy
 *   12..20 g_sensitivity xx xy xz yx yy yz zx zy zz    (none)
 *
 * M_xy is row x, column y.
 *
 * Two builds from the same source: double (the default) and float, when IMUFIT_RUNTIME_FLOAT is
 * defined. The float build uses float arithmetic throughout and calls no double-precision routine
 * (tests/c_runtime_cortex_m4.cmake checks the object for a Cortex-M4F); its names end in _f
 * (imufit_calibration_f, imufit_correct_f, ...), so a program may include this header twice, once
 * with IMUFIT_RUNTIME_FLOAT defined, and link both builds.
 *
 * The calibration blob (`imufit export --format bin`), for EEPROM: little-endian, packed, its
 * layout below; every number a binary64 whatever the build, converted to float by the float build
 * with integer arithmetic (round to nearest even, as a compiler converts). imufit_load_blob()
 * checks the magic, version, length and CRC-32 (IEEE 802.3, the zlib one) before it uses anything.
 *
 *   offset  bytes  field
 *   0       4      magic "IMUC"
 *   4       2      format version, 1
 *   6       2      reserved, 0
 *   8       4      length of the whole blob in bytes, CRC included (1192)
 *   12      64     serial, ASCII, NUL-padded (at most 63 characters)
 *   76      32     SHA-256 of the calibration file the blob was made from
 *   108     8      reference temperature T_ref, degC
 *   116     8      temp_min_c, degC: the fitted range, the clamp
 *   124     8      temp_max_c, degC
 *   132     672    gyro coefficients, 21 rows of c0..c3, row-major
 *   804     384    accel coefficients, 12 rows of c0..c3
 *   1188    4      CRC-32 of bytes 0..1187
 */
#ifndef IMUFIT_RUNTIME_H_COMMON_
#define IMUFIT_RUNTIME_H_COMMON_

#include <stddef.h>
#include <stdint.h>

#define IMUFIT_POLYNOMIAL_TERMS 4
#define IMUFIT_GYRO_COEFFICIENTS 21
#define IMUFIT_ACCEL_COEFFICIENTS 12
#define IMUFIT_SERIAL_BYTES 64
#define IMUFIT_SHA256_BYTES 32

/* The blob's layout (above). */
#define IMUFIT_BLOB_VERSION 1
#define IMUFIT_BLOB_MAGIC "IMUC"
#define IMUFIT_BLOB_OFFSET_VERSION 4
#define IMUFIT_BLOB_OFFSET_LENGTH 8
#define IMUFIT_BLOB_OFFSET_SERIAL 12
#define IMUFIT_BLOB_OFFSET_SHA256 76
#define IMUFIT_BLOB_OFFSET_REFERENCE 108
#define IMUFIT_BLOB_OFFSET_TEMP_MIN 116
#define IMUFIT_BLOB_OFFSET_TEMP_MAX 124
#define IMUFIT_BLOB_OFFSET_GYRO 132
#define IMUFIT_BLOB_OFFSET_ACCEL 804
#define IMUFIT_BLOB_OFFSET_CRC 1188
#define IMUFIT_BLOB_BYTES 1192

/* What the functions return. */
#define IMUFIT_OK 0
#define IMUFIT_TEMP_CLAMPED 1     /* imufit_correct: the temperature was outside the fitted range */
#define IMUFIT_ERROR_SIZE (-1)    /* the buffer is shorter than the blob says or than a blob is */
#define IMUFIT_ERROR_MAGIC (-2)   /* not an imufit calibration blob */
#define IMUFIT_ERROR_VERSION (-3) /* a blob version this runtime does not read */
#define IMUFIT_ERROR_LENGTH (-4)  /* the length field is not IMUFIT_BLOB_BYTES */
#define IMUFIT_ERROR_CRC (-5)     /* the CRC-32 does not match: the blob is damaged */
#define IMUFIT_ERROR_VALUE                                               \
  (-6) /* a number is not finite (or beyond float), a range is inverted, \
          or the serial is not NUL-terminated */

#endif /* IMUFIT_RUNTIME_H_COMMON_ */

/* The declarations of one build: once for double, once for float. */
#if defined(IMUFIT_RUNTIME_FLOAT) && !defined(IMUFIT_RUNTIME_H_FLOAT_)
#define IMUFIT_RUNTIME_H_FLOAT_
#define IMUFIT_RUNTIME_DECLARE_
#define IMUFIT_REAL_ float
#define IMUFIT_NAME_(name) name##_f
#elif !defined(IMUFIT_RUNTIME_FLOAT) && !defined(IMUFIT_RUNTIME_H_DOUBLE_)
#define IMUFIT_RUNTIME_H_DOUBLE_
#define IMUFIT_RUNTIME_DECLARE_
#define IMUFIT_REAL_ double
#define IMUFIT_NAME_(name) name
#endif

#ifdef IMUFIT_RUNTIME_DECLARE_
#undef IMUFIT_RUNTIME_DECLARE_

#ifdef __cplusplus
extern "C" {
#endif

/* One unit's calibration. `imufit export --format c` writes an initializer for it. */
typedef struct IMUFIT_NAME_(imufit_calibration) {
  char serial[IMUFIT_SERIAL_BYTES];          /* NUL-terminated */
  unsigned char sha256[IMUFIT_SHA256_BYTES]; /* of the calibration file */
  IMUFIT_REAL_ reference_temp_c;             /* T_ref of dT = T - T_ref, degC */
  IMUFIT_REAL_ temp_min_c;                   /* the fitted range: T is clamped to it, degC */
  IMUFIT_REAL_ temp_max_c;
  IMUFIT_REAL_ gyro[IMUFIT_GYRO_COEFFICIENTS][IMUFIT_POLYNOMIAL_TERMS];
  IMUFIT_REAL_ accel[IMUFIT_ACCEL_COEFFICIENTS][IMUFIT_POLYNOMIAL_TERMS];
} IMUFIT_NAME_(imufit_calibration);

/* Corrects one sample: temp_c the unit's temperature reading (degC), gyro_raw and accel_raw its
 * raw outputs; writes omega_radps (rad/s) and a_mps2 (m/s^2), body frame. Returns IMUFIT_OK, or
 * IMUFIT_TEMP_CLAMPED when temp_c lay outside [temp_min_c, temp_max_c] (or was NaN) and the
 * coefficients were taken at the nearest end of the range. The outputs may alias the inputs. */
int IMUFIT_NAME_(imufit_correct)(const IMUFIT_NAME_(imufit_calibration) * calibration, IMUFIT_REAL_ temp_c,
                                 const IMUFIT_REAL_ gyro_raw[3], const IMUFIT_REAL_ accel_raw[3],
                                 IMUFIT_REAL_ omega_radps[3], IMUFIT_REAL_ a_mps2[3]);

/* Validates a blob of `size` bytes (magic, version, length, CRC-32, then every value) and only
 * then fills `calibration`. Returns IMUFIT_OK or an IMUFIT_ERROR_*; on an error `calibration` is
 * left as it was. */
int IMUFIT_NAME_(imufit_load_blob)(const unsigned char* blob, size_t size,
                                   IMUFIT_NAME_(imufit_calibration) * calibration);

/* CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320, as zlib's crc32()) of `size` bytes. */
uint32_t IMUFIT_NAME_(imufit_crc32)(const unsigned char* data, size_t size);

#ifdef __cplusplus
}
#endif

#undef IMUFIT_REAL_
#undef IMUFIT_NAME_
#endif /* IMUFIT_RUNTIME_DECLARE_ */
