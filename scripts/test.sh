#!/usr/bin/env bash
# The whole test suite, from a fresh Debian machine: installs what is missing, checks that the C++
# is formatted as .clang-format says (a few seconds, before any build), then builds and runs
# every test with ctest twice: in a Release build (build-release/) and in a build with
# AddressSanitizer and UndefinedBehaviorSanitizer (build-sanitize/, -DIMUFIT_SANITIZE=ON); after the
# Release tests, the Python module's tests with pytest (python/tests); at the end, when clang with
# libFuzzer is installed, a short run (12 s) of every fuzz target (scripts/fuzz.sh, build-fuzz/).
# Exits non-zero on the first failure. This is what CI runs (.ci/run).
#
#   bash scripts/test.sh
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

jobs=$(nproc 2>/dev/null || echo 2)
# A sanitizer finding is an error: stop at the first one, with a stack.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:strict_string_checks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

run_suite() {  # run_suite NAME DIR
  imufit_say "$1: built in $((SECONDS - started)) s; running the tests"
  (cd "$2" && ctest --output-on-failure --timeout 900 -j "$jobs")
}

# Every tracked C/C++ file as clang-format formats it (.clang-format: Google style, 110 columns);
# the files that are not are listed with the command that fixes them.
check_format() {
  if ! git -C "$IMUFIT_ROOT" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    imufit_say "not a git checkout: the format check is skipped"
    return 0
  fi
  local files=() unformatted=()
  mapfile -t files < <(git -C "$IMUFIT_ROOT" ls-files -- '*.cc' '*.h' '*.cpp' '*.hpp' ':!fixtures/')
  imufit_say "format: clang-format --dry-run --Werror on ${#files[@]} tracked C/C++ files ($(clang-format --version))"
  mapfile -t unformatted < <(cd "$IMUFIT_ROOT" && clang-format --dry-run --Werror "${files[@]}" 2>&1 |
                               sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: error: .*/\1/p' | sort -u)
  if [[ ${#unformatted[@]} -gt 0 ]]; then
    printf '  %s\n' "${unformatted[@]}" >&2
    imufit_die "${#unformatted[@]} of ${#files[@]} C/C++ files are not formatted as .clang-format says;" \
      "fix them with: clang-format -i FILE... (from the top of the clone)"
  fi
}

imufit_install_deps "${IMUFIT_APT_PACKAGES[@]}" "${IMUFIT_TEST_APT_PACKAGES[@]}"
check_format

imufit_say "Release build (build-release/)"
started=$SECONDS
# Tests, benchmarks and the Python module on (scripts/example.sh builds without them), and every
# warning of the project's own code an error (IMUFIT_WERROR).
imufit_build "$IMUFIT_ROOT/build-release" -- "${IMUFIT_TEST_CMAKE_ARGS[@]}"
run_suite Release "$IMUFIT_ROOT/build-release"

# The Python module (python/), when this build has it: pytest against the Release build's module and
# command, with the interpreter CMake built it for.
cache=$IMUFIT_ROOT/build-release/CMakeCache.txt
if grep -q '^IMUFIT_BUILD_PYTHON:BOOL=ON' "$cache"; then
  imufit_say "Python module: pytest (python/tests)"
  python=$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' "$cache")
  PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$IMUFIT_ROOT/build-release/python" \
    IMUFIT_BINARY="$IMUFIT_ROOT/build-release/app/imufit" "$python" -m pytest -q -p no:cacheprovider "$IMUFIT_ROOT/python/tests"
else
  imufit_say "Python module not built (pybind11 or the Python headers not found): pytest skipped"
fi

imufit_say "AddressSanitizer + UndefinedBehaviorSanitizer build (build-sanitize/)"
started=$SECONDS
# -O1: the sanitizers need no more, and the Ceres-heavy sources compile in about half the time.
# No Python module: an ASan-built extension cannot be loaded into an uninstrumented interpreter.
# Warnings are gated by the Release build (IMUFIT_WERROR above); at -O1 under the sanitizers'
# instrumentation GCC 12 warns of what it cannot prove (-Wformat-truncation, -Wmaybe-uninitialized),
# so this build reports warnings without failing on them.
imufit_build "$IMUFIT_ROOT/build-sanitize" -- -DIMUFIT_SANITIZE=ON -DIMUFIT_BUILD_BENCH=OFF -DIMUFIT_BUILD_PYTHON=OFF \
  -DIMUFIT_WERROR=OFF "-DCMAKE_CXX_FLAGS_RELEASE=-O1 -DNDEBUG"
run_suite "ASan+UBSan" "$IMUFIT_ROOT/build-sanitize"

# The readers under libFuzzer, briefly (scripts/fuzz.sh --seconds N for a campaign).
if imufit_fuzz_available; then
  bash "$IMUFIT_ROOT/scripts/fuzz.sh" --seconds "${IMUFIT_FUZZ_SECONDS:-12}"
else
  imufit_say "clang++ with libFuzzer not found: the fuzz targets are skipped (apt-get install clang libfuzzer-14-dev)"
fi
