# Shared by scripts/example.sh and scripts/test.sh (sourced, not run): installs what is missing
# on a Debian machine and configures and builds imufit. Idempotent: a second run installs nothing
# and rebuilds only what changed.
# shellcheck shell=bash

IMUFIT_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# What building imufit (the command, tests, benchmarks and Python module left out) and running
# scripts/example.sh need, as Debian packages: the compiler and build tools, and every library the
# build's CMake requires (Eigen and Ceres, yaml-cpp, CLI11, zlib, OpenSSL's libcrypto, ISA-L,
# SQLite and PostgreSQL's libpq for the results store, ROS 1's rosbag_storage and sensor_msgs for
# sessions recorded as bags). scripts/example.sh configures with
# IMUFIT_EXAMPLE_CMAKE_ARGS, so that GoogleTest, Google Benchmark and pybind11 are not needed;
# scripts/test.sh turns them on again in the same build folder (IMUFIT_TEST_CMAKE_ARGS).
IMUFIT_APT_PACKAGES=(cmake ninja-build g++ pkg-config libceres-dev libeigen3-dev libyaml-cpp-dev libcli11-dev
                     zlib1g-dev libssl-dev libisal-dev libsqlite3-dev libpq-dev librosbag-storage-dev
                     libsensor-msgs-dev)
IMUFIT_EXAMPLE_CMAKE_ARGS=(-DIMUFIT_BUILD_TESTS=OFF -DIMUFIT_BUILD_BENCH=OFF -DIMUFIT_BUILD_PYTHON=OFF)

# What the whole suite needs besides (scripts/test.sh): GoogleTest and Google Benchmark, the
# Python module's build and tests, gnuplot for the plots, Chromium and poppler-utils for the
# printed certificates, a PostgreSQL server for the store's tests, the ARM cross-compiler for the
# C runtime's Cortex-M4 build, clang with libFuzzer and clang-format, ccache, JSON Schema, ROS's
# Python rosbag and sensor_msgs (the tests write bags with ROS's own writer).
IMUFIT_TEST_CMAKE_ARGS=(-DIMUFIT_BUILD_TESTS=ON -DIMUFIT_BUILD_BENCH=ON -UIMUFIT_BUILD_PYTHON -DIMUFIT_WERROR=ON)
IMUFIT_TEST_APT_PACKAGES=(libgtest-dev libbenchmark-dev gnuplot-nox pybind11-dev python3-pybind11 python3-dev
                          python3-numpy python3-pytest python3-yaml python3-matplotlib python3-setuptools
                          python3-wheel python3-pip clang clang-format libfuzzer-14-dev chromium poppler-utils
                          ccache gcc-arm-none-eabi libnewlib-arm-none-eabi python3-jsonschema postgresql
                          python3-rosbag python3-sensor-msgs)

# True when clang++ can link a libFuzzer program (scripts/fuzz.sh).
imufit_fuzz_available() {
  command -v clang++ >/dev/null 2>&1 || return 1
  local probe
  probe=$(mktemp -d "${TMPDIR:-/tmp}/imufit_fuzz_probe.XXXXXX")
  printf '#include <cstdint>\n#include <cstddef>\nextern "C" int LLVMFuzzerTestOneInput(const uint8_t*, size_t) { return 0; }\n' \
    >"$probe/probe.cc"
  local ok=1
  clang++ -fsanitize=fuzzer "$probe/probe.cc" -o "$probe/probe" >/dev/null 2>&1 && ok=0
  rm -rf "$probe"
  return $ok
}

imufit_say() { printf '== %s\n' "$*"; }
imufit_die() { printf 'error: %s\n' "$*" >&2; exit 1; }

# imufit_install_deps PACKAGE...: installs those of the Debian packages named that are not
# installed yet (apt-get update first; sudo only when not root).
imufit_install_deps() {
  if ! command -v dpkg-query >/dev/null 2>&1; then
    imufit_say "not a Debian system: make sure these are installed: $*"
    return 0
  fi
  local missing=() package
  for package in "$@"; do
    if [[ $(dpkg-query -W -f='${db:Status-Status}' "$package" 2>/dev/null) != installed ]]; then
      missing+=("$package")
    fi
  done
  if [[ ${#missing[@]} -eq 0 ]]; then
    return 0
  fi
  local sudo=()
  if [[ $(id -u) != 0 ]]; then
    command -v sudo >/dev/null 2>&1 || imufit_die "need root or sudo to install: ${missing[*]}"
    sudo=(sudo)
  fi
  imufit_say "installing ${missing[*]}"
  local log
  log=$(mktemp "${TMPDIR:-/tmp}/imufit_apt.XXXXXX")
  if ! { "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q &&
         "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
           "${missing[@]}"; } >"$log" 2>&1 </dev/null; then
    cat "$log" >&2
    rm -f "$log"
    imufit_die "apt-get could not install ${missing[*]}"
  fi
  rm -f "$log"
}

# imufit_build DIR [TARGET...] [-- CMAKE_ARGS...]: configures DIR (Ninja, Release unless the
# arguments say otherwise) and builds the targets (all when none). Quiet unless something fails.
imufit_build() {
  local dir=$1
  shift
  local targets=() cmake_args=()
  while [[ $# -gt 0 && $1 != -- ]]; do targets+=("$1"); shift; done
  [[ $# -gt 0 ]] && shift
  cmake_args=("$@")
  if command -v ccache >/dev/null 2>&1; then
    cmake_args+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
    # Paths below the checkout count as relative, so another clone (CI's) reuses the cache.
    export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$IMUFIT_ROOT}
  fi
  mkdir -p "$dir"
  if ! cmake -S "$IMUFIT_ROOT" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "${cmake_args[@]}" \
       >"$dir/configure.log" 2>&1; then
    cat "$dir/configure.log" >&2
    imufit_die "cmake could not configure $dir"
  fi
  # --quiet (ninja 1.11+) drops the progress lines; compiler messages still show. With pipefail
  # the pipeline fails when ninja does.
  local quiet=()
  if grep -q -- '--quiet' <<<"$(ninja --help 2>&1)"; then quiet=(--quiet); fi
  if ! ninja -C "$dir" "${quiet[@]}" "${targets[@]}" | { grep -v '^ninja: no work to do\.$' || true; }; then
    imufit_die "the build in $dir failed"
  fi
}
