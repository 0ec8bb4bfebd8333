/* imufit — the correction model for firmware (imufit_runtime.h has the equations, the layouts and
 * the clamping policy). Compile with -DIMUFIT_RUNTIME_FLOAT for the float build. */
#include "imufit_runtime.h"

#ifdef IMUFIT_RUNTIME_FLOAT
typedef float real;
#define NAME(name) name##_f
#else
typedef double real;
#define NAME(name) name
#endif
typedef NAME(imufit_calibration) calibration_t;

/* Row and column of the six off-diagonal misalignment terms, in coefficient order. */
static const int kMisalignmentRow[6] = {0, 0, 1, 1, 2, 2};
static const int kMisalignmentCol[6] = {1, 2, 0, 2, 0, 1};

enum { kBias = 0, kScale = 3, kMisalignment = 6, kGSensitivity = 12 };

/* c0 + x (c1 + x (c2 + x c3)), as temperature_polynomial.h evaluates it. */
static real Horner(const real c[IMUFIT_POLYNOMIAL_TERMS], real x) {
  return c[0] + x * (c[1] + x * (c[2] + x * c[3]));
}

/* The misalignment matrix at x: unit diagonal, the six terms off it. */
static void Misalignment(const real (*rows)[IMUFIT_POLYNOMIAL_TERMS], real x, real m[3][3]) {
  int i;
  m[0][0] = 1;
  m[1][1] = 1;
  m[2][2] = 1;
  for (i = 0; i < 6; ++i) m[kMisalignmentRow[i]][kMisalignmentCol[i]] = Horner(rows[kMisalignment + i], x);
}

/* out = M * diag(1/S) * unbiased, with S and M from `rows` at x (sensor_model.h's CorrectSensor). */
static void ScaleAndAlign(const real (*rows)[IMUFIT_POLYNOMIAL_TERMS], real x, const real unbiased[3],
                          real out[3]) {
  real m[3][3];
  real scaled[3];
  int axis;
  for (axis = 0; axis < 3; ++axis) scaled[axis] = unbiased[axis] / Horner(rows[kScale + axis], x);
  Misalignment(rows, x, m);
  for (axis = 0; axis < 3; ++axis) {
    out[axis] = m[axis][0] * scaled[0] + m[axis][1] * scaled[1] + m[axis][2] * scaled[2];
  }
}

int NAME(imufit_correct)(const calibration_t* calibration, real temp_c, const real gyro_raw[3],
                         const real accel_raw[3], real omega_radps[3], real a_mps2[3]) {
  int status = IMUFIT_OK;
  real x;
  real unbiased[3];
  real h_a[3];
  real a_hat[3];
  int axis;
  if (!(temp_c >= calibration->temp_min_c)) { /* below the range, or NaN */
    temp_c = calibration->temp_min_c;
    status = IMUFIT_TEMP_CLAMPED;
  } else if (temp_c > calibration->temp_max_c) {
    temp_c = calibration->temp_max_c;
    status = IMUFIT_TEMP_CLAMPED;
  }
  x = temp_c - calibration->reference_temp_c;

  /* The accelerometer first: its corrected output is the gyro's specific force. */
  for (axis = 0; axis < 3; ++axis)
    unbiased[axis] = accel_raw[axis] - Horner(calibration->accel[kBias + axis], x);
  ScaleAndAlign(calibration->accel, x, unbiased, a_hat);

  for (axis = 0; axis < 3; ++axis) {
    const real(*h)[IMUFIT_POLYNOMIAL_TERMS] = calibration->gyro + kGSensitivity + 3 * axis;
    h_a[axis] = Horner(h[0], x) * a_hat[0] + Horner(h[1], x) * a_hat[1] + Horner(h[2], x) * a_hat[2];
  }
  for (axis = 0; axis < 3; ++axis) {
    unbiased[axis] = (gyro_raw[axis] - Horner(calibration->gyro[kBias + axis], x)) - h_a[axis];
  }
  ScaleAndAlign(calibration->gyro, x, unbiased, omega_radps);
  for (axis = 0; axis < 3; ++axis) a_mps2[axis] = a_hat[axis];
  return status;
}

uint32_t NAME(imufit_crc32)(const unsigned char* data, size_t size) {
  uint32_t crc = 0xFFFFFFFFu;
  size_t i;
  int bit;
  for (i = 0; i < size; ++i) {
    crc ^= data[i];
    for (bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return crc ^ 0xFFFFFFFFu;
}

static uint32_t Read32(const unsigned char* p) {
  return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static uint64_t Read64(const unsigned char* p) {
  return (uint64_t)Read32(p) | ((uint64_t)Read32(p + 4) << 32);
}

#ifdef IMUFIT_RUNTIME_FLOAT
/* The float nearest to the binary64 with these bits (ties to even), by integer arithmetic: no
 * double-precision routine on a single-precision FPU. Returns 0 for a value that is not finite or
 * that rounds beyond the largest float. */
static int RealFromBits(uint64_t bits, real* value) {
  const uint32_t sign = (uint32_t)(bits >> 63) << 31;
  const int biased = (int)((bits >> 52) & 0x7FF);
  const uint64_t significand = (bits & 0xFFFFFFFFFFFFFull) | ((uint64_t)1 << 52); /* 53 bits */
  int exponent = biased - 1023;
  int shift;
  uint64_t kept, rest, half;
  union {
    uint32_t u;
    float f;
  } out;
  if (biased == 0x7FF) return 0;             /* infinity or NaN */
  if (biased == 0 || exponent < -126 - 25) { /* zero, or below half the smallest float */
    out.u = sign;
    *value = out.f;
    return 1;
  }
  /* Keep 24 significant bits for a normal float, fewer for a subnormal one. */
  shift = exponent >= -126 ? 29 : 29 + (-126 - exponent);
  kept = significand >> shift;
  rest = significand & (((uint64_t)1 << shift) - 1);
  half = (uint64_t)1 << (shift - 1);
  if (rest > half || (rest == half && (kept & 1))) ++kept;
  if (exponent >= -126) {
    if (kept == ((uint64_t)1 << 24)) { /* rounding carried into the next power of two */
      kept >>= 1;
      ++exponent;
    }
    if (exponent > 127) return 0;
    out.u = sign | ((uint32_t)(exponent + 127) << 23) | ((uint32_t)kept & 0x7FFFFFu);
  } else {
    out.u = sign | (uint32_t)kept; /* a carry into bit 23 is the smallest normal float */
  }
  *value = out.f;
  return 1;
}
#else
static int RealFromBits(uint64_t bits, real* value) {
  union {
    uint64_t u;
    double d;
  } in;
  if (((bits >> 52) & 0x7FF) == 0x7FF) return 0; /* infinity or NaN */
  in.u = bits;
  *value = in.d;
  return 1;
}
#endif

/* Reads `count` binary64 numbers at `p` into `out`, or only checks them when `out` is null. */
static int ReadReals(const unsigned char* p, int count, real* out) {
  real value;
  int i;
  for (i = 0; i < count; ++i) {
    if (!RealFromBits(Read64(p + 8 * i), &value)) return 0;
    if (out != 0) out[i] = value;
  }
  return 1;
}

/* Reads the numbers of a blob whose framing has been checked into `calibration`, or only checks
 * them when it is null (so that a bad blob leaves the caller's calibration as it was, without a
 * copy of the whole struct: no memcpy). */
static int ReadNumbers(const unsigned char* blob, calibration_t* calibration) {
  const int terms = IMUFIT_POLYNOMIAL_TERMS;
  real range[2];
  int row;
  if (!ReadReals(blob + IMUFIT_BLOB_OFFSET_TEMP_MIN, 1, &range[0]) ||
      !ReadReals(blob + IMUFIT_BLOB_OFFSET_TEMP_MAX, 1, &range[1]) || !(range[0] <= range[1])) {
    return 0;
  }
  if (!ReadReals(blob + IMUFIT_BLOB_OFFSET_REFERENCE, 1, calibration ? &calibration->reference_temp_c : 0)) {
    return 0;
  }
  for (row = 0; row < IMUFIT_GYRO_COEFFICIENTS; ++row) {
    if (!ReadReals(blob + IMUFIT_BLOB_OFFSET_GYRO + 8 * terms * row, terms,
                   calibration ? calibration->gyro[row] : 0)) {
      return 0;
    }
  }
  for (row = 0; row < IMUFIT_ACCEL_COEFFICIENTS; ++row) {
    if (!ReadReals(blob + IMUFIT_BLOB_OFFSET_ACCEL + 8 * terms * row, terms,
                   calibration ? calibration->accel[row] : 0)) {
      return 0;
    }
  }
  if (calibration != 0) {
    calibration->temp_min_c = range[0];
    calibration->temp_max_c = range[1];
  }
  return 1;
}

int NAME(imufit_load_blob)(const unsigned char* blob, size_t size, calibration_t* calibration) {
  const char* magic = IMUFIT_BLOB_MAGIC;
  int i;
  if (blob == 0 || size < IMUFIT_BLOB_OFFSET_SERIAL) return IMUFIT_ERROR_SIZE;
  for (i = 0; i < 4; ++i) {
    if (blob[i] != (unsigned char)magic[i]) return IMUFIT_ERROR_MAGIC;
  }
  if ((blob[IMUFIT_BLOB_OFFSET_VERSION] | (blob[IMUFIT_BLOB_OFFSET_VERSION + 1] << 8)) !=
      IMUFIT_BLOB_VERSION) {
    return IMUFIT_ERROR_VERSION;
  }
  if (Read32(blob + IMUFIT_BLOB_OFFSET_LENGTH) != IMUFIT_BLOB_BYTES) return IMUFIT_ERROR_LENGTH;
  if (size < IMUFIT_BLOB_BYTES) return IMUFIT_ERROR_SIZE;
  if (NAME(imufit_crc32)(blob, IMUFIT_BLOB_OFFSET_CRC) != Read32(blob + IMUFIT_BLOB_OFFSET_CRC)) {
    return IMUFIT_ERROR_CRC;
  }
  if (blob[IMUFIT_BLOB_OFFSET_SERIAL + IMUFIT_SERIAL_BYTES - 1] != 0 || !ReadNumbers(blob, 0)) {
    return IMUFIT_ERROR_VALUE;
  }
  ReadNumbers(blob, calibration);
  for (i = 0; i < IMUFIT_SERIAL_BYTES; ++i)
    calibration->serial[i] = (char)blob[IMUFIT_BLOB_OFFSET_SERIAL + i];
  for (i = 0; i < IMUFIT_SHA256_BYTES; ++i) calibration->sha256[i] = blob[IMUFIT_BLOB_OFFSET_SHA256 + i];
  return IMUFIT_OK;
}
