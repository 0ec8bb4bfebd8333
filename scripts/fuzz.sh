#!/usr/bin/env bash
# Fuzzes the readers of io/ with libFuzzer (fuzz/, docs/fuzzing.md): builds the targets with clang
# in build-fuzz/ (-DIMUFIT_BUILD_FUZZ=ON: ASan, UBSan, 64-byte CSV blocks), seeds each target's
# corpus from fixtures/ and fuzz/seeds/, and runs every target for SECONDS (default 600: a
# campaign; scripts/test.sh runs 12 s each). The corpora grow in build-fuzz/corpus/TARGET and are
# reused by the next run; a crash, leak, timeout or failed oracle stops with the input saved in
# build-fuzz/artifacts/ (replay: build-fuzz/fuzz/TARGET FILE).
#
#   bash scripts/fuzz.sh [--seconds N] [--jobs J] [TARGET...]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

seconds=600
jobs=1
targets=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --seconds) seconds=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    -h|--help) sed -n '2,10p' "${BASH_SOURCE[0]}"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
[[ ${#targets[@]} -gt 0 ]] || targets=(fuzz_samples fuzz_plan fuzz_calibration fuzz_limits fuzz_series fuzz_ulog fuzz_rosbag)

imufit_fuzz_available || imufit_die "fuzzing needs clang++ with libFuzzer (Debian: apt-get install clang libfuzzer-14-dev)"

dir=$IMUFIT_ROOT/build-fuzz
imufit_say "libFuzzer build (build-fuzz/)"
CC=clang CXX=clang++ imufit_build "$dir" imufit_fuzz -- -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DIMUFIT_BUILD_FUZZ=ON \
  -DIMUFIT_BUILD_TESTS=OFF -DIMUFIT_BUILD_BENCH=OFF -DIMUFIT_BUILD_PYTHON=OFF

# Seeds: the fixtures (plans, calibrations; the first rows of each samples file, plain and gzip).
seeds=$dir/seeds
rm -rf "$seeds"
mkdir -p "$seeds"/{fuzz_samples,fuzz_plan,fuzz_calibration,fuzz_limits,fuzz_series,fuzz_ulog,fuzz_rosbag}
cp "$IMUFIT_ROOT"/fixtures/plan_*.yaml "$IMUFIT_ROOT"/fixtures/hand_*.yaml "$seeds/fuzz_plan/"
cp "$IMUFIT_ROOT"/fixtures/*_truth.yaml "$IMUFIT_ROOT"/fixtures/golden/*.yaml "$seeds/fuzz_calibration/"
cp "$IMUFIT_ROOT"/fuzz/seeds/limits*.yaml "$seeds/fuzz_limits/"
# Small bags written by ROS's own rosbag (plain, LZ4, BZ2; with and without a temperature topic).
cp "$IMUFIT_ROOT"/fuzz/seeds/rosbag/*.bag "$seeds/fuzz_rosbag/"
# PX4 ULogs written from the format specification (python/tests/ulog_writer.py): a session amid the
# other message types, two instances, appended data after a message cut short.
cp "$IMUFIT_ROOT"/fuzz/seeds/ulog_*.ulg "$seeds/fuzz_ulog/"
# Inputs that once failed (fuzz/regressions/TARGET/): run first, every time.
for regressions in "$IMUFIT_ROOT"/fuzz/regressions/*/; do
  cp "$regressions"* "$seeds/$(basename "$regressions")/"
done
for samples in "$IMUFIT_ROOT"/fixtures/*.csv.gz; do
  name=$(basename "$samples" .csv.gz)
  # (zcat ends early when head has enough: its broken pipe is expected)
  { zcat "$samples" || true; } | head -n 40 >"$seeds/fuzz_samples/$name.csv"
  gzip -9 -n -c "$seeds/fuzz_samples/$name.csv" >"$seeds/fuzz_samples/$name.csv.gz"
  cp "$seeds/fuzz_samples/$name.csv" "$seeds/fuzz_samples/$name.csv.gz" "$seeds/fuzz_series/"
done

mkdir -p "$dir/artifacts"
# The targets write each input to a file: keep those under build-fuzz/.
export TMPDIR=$dir/tmp
rm -rf "$TMPDIR"
mkdir -p "$TMPDIR"
status=0
for target in "${targets[@]}"; do
  corpus=$dir/corpus/$target
  mkdir -p "$corpus"
  imufit_say "$target: ${seconds} s"
  log=$dir/$target.log
  # -rss_limit_mb: the readers' limits keep memory bounded; -timeout: no input may take 10 s.
  # -max_len: a bag's header record alone is padded to 4 kB, and message definitions follow.
  max_len=8192
  [[ $target != fuzz_rosbag ]] || max_len=32768
  if ! (cd "$dir" && "$dir/fuzz/$target" "$corpus" "$seeds/$target" -max_total_time="$seconds" \
          -timeout=10 -rss_limit_mb=2048 -max_len="$max_len" -jobs="$jobs" -workers="$jobs" \
          -print_final_stats=1 -artifact_prefix="$dir/artifacts/$target-" >"$log" 2>&1); then
    tail -n 60 "$log" >&2
    imufit_say "$target FAILED: see $log and $dir/artifacts/"
    status=1
    continue
  fi
  grep -E '^stat::(number_of_executed_units|peak_rss_mb|new_units_added)' "$log" | tr '\n' ' ' | sed 's/$/\n/' || true
done
rm -rf "$TMPDIR"
exit $status
