#!/usr/bin/env bash
# The bundled example, from a fresh Debian machine: installs what is missing, builds imufit
# (Release, in build-release/), simulates a temperature-soak run of the MEMS unit of
# fixtures/mems_truth.yaml over fixtures/plan_6pos.yaml, fits it with `imufit fit`, corrects the
# run with the fitted calibration (`imufit apply`) and prints how far the corrected outputs are
# from the truth. Everything it writes goes to build-release/example/.
#
#   bash scripts/example.sh
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

imufit_install_deps "${IMUFIT_APT_PACKAGES[@]}"  # what the build and the example need, nothing for the tests
imufit_say "building imufit (Release, build-release/)"
build=$IMUFIT_ROOT/build-release
imufit_build "$build" imufit -- "${IMUFIT_EXAMPLE_CMAKE_ARGS[@]}"
imufit=$build/app/imufit
fixtures=$IMUFIT_ROOT/fixtures
out=$build/example
mkdir -p "$out"

imufit_say "simulating a soak at -35, -10, 25, 55, 80 degC (fixtures/plan_6pos.yaml, fixtures/mems_truth.yaml)"
"$imufit" simulate --plan "$fixtures/plan_6pos.yaml" --calibration "$fixtures/mems_truth.yaml" \
  -o "$out/raw.csv" --truth "$out/truth.csv" --temps=-35,-10,25,55,80 --rate 50 --dwell 5 --transition 1 \
  --gyro-noise-density 8.7e-5 --gyro-bias-instability 2.4e-5 --accel-noise-density 1.5e-3 \
  --accel-bias-instability 6e-4 --temp-noise 0.05 --quantize --seed 1

imufit_say "fitting the calibration (imufit fit)"
calibration=$out/calibration.yaml
"$imufit" fit --plan "$fixtures/plan_6pos.yaml" --samples "$out/raw.csv" -o "$calibration"

imufit_say "correcting the run (imufit apply)"
"$imufit" apply --calibration "$calibration" --samples "$out/raw.csv" -o "$out/corrected.csv"

# Summary. Errors of segment means (the average over each stretch the table held still or turned
# steadily) show calibration errors; the per-sample RMS also holds the sensor noise. "Nominal
# scale only" is the raw output divided by the data-sheet sensitivity (16.4 LSB per deg/s,
# 2048 LSB per g): what one gets without a calibration.
imufit_say "summary: corrected with the fitted calibration, compared with the truth (transitions left out)"
strip() { grep -v '^#' "$1"; }
paste -d, <(strip "$out/corrected.csv") <(strip "$out/truth.csv") <(strip "$out/raw.csv") | awk -F, '
  function abs(x) { return x < 0 ? -x : x }
  function close_occurrence(   i, e) {
    if (n == 0) return
    for (i = 0; i < 6; ++i) {
      e = abs(sum_hat[i] / n - sum_true[i] / n) * unit[i]
      if (e > worst_hat[i < 3 ? 0 : 1]) worst_hat[i < 3 ? 0 : 1] = e
      e = abs(sum_nominal[i] / n - sum_true[i] / n) * unit[i]
      if (e > worst_nominal[i < 3 ? 0 : 1]) worst_nominal[i < 3 ? 0 : 1] = e
      sum_hat[i] = sum_true[i] = sum_nominal[i] = 0
    }
    ++occurrences
    n = 0
  }
  BEGIN {
    pi = 3.14159265358979; g = 9.80665
    for (i = 0; i < 3; ++i) { unit[i] = 180 / pi; unit[i + 3] = 1000 / g }  # deg/s and mg
    gyro_lsb = 16.4 * 180 / pi; accel_lsb = 2048 / g                        # nominal sensitivities
  }
  NR == 1 { next }
  {
    segment = $3
    if (segment != last) close_occurrence()
    last = segment
    if (segment == -1) next
    for (i = 0; i < 6; ++i) {
      hat = $(4 + i); truth = $(13 + i); nominal = $(22 + i) / (i < 3 ? gyro_lsb : accel_lsb)
      sum_hat[i] += hat; sum_true[i] += truth; sum_nominal[i] += nominal
      d = (hat - truth) * unit[i]
      sq[i < 3 ? 0 : 1] += d * d
    }
    ++n; ++samples
  }
  END {
    close_occurrence()
    printf "  %d samples in %d segment occurrences\n", samples, occurrences
    printf "  %-44s %14s %12s\n", "", "gyro (deg/s)", "accel (mg)"
    printf "  %-44s %14.4f %12.3f\n", "nominal scale only: worst segment-mean error", worst_nominal[0], worst_nominal[1]
    printf "  %-44s %14.4f %12.3f\n", "corrected: worst segment-mean error", worst_hat[0], worst_hat[1]
    printf "  %-44s %14.4f %12.3f\n", "corrected: per-sample RMS error (with noise)", sqrt(sq[0] / (3 * samples)), sqrt(sq[1] / (3 * samples))
  }'
imufit_say "files: $out/{raw,truth,corrected}.csv, calibration: $calibration"
