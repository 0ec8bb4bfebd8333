#!/usr/bin/env bash
# Compiles the C runtime (model/c/imufit_runtime.c) as a check, in one of two modes:
#
#   c_runtime_compile.sh strict SOURCE_DIR WORK_DIR CC
#       both builds (double, float) with the host C compiler CC as strict C99: -std=c99 -Wall -Wextra
#       -Werror -pedantic (and -Wdouble-promotion -Wconversion).
#   c_runtime_compile.sh cortex-m4 SOURCE_DIR WORK_DIR
#       the float build for a Cortex-M4F with Debian's arm-none-eabi-gcc (-mcpu=cortex-m4
#       -mfpu=fpv4-sp-d16 -mfloat-abi=hard -Os); fails when the object leaves any symbol undefined:
#       a double-precision routine (__aeabi_d*, a libm function without the f suffix) or anything
#       from libc; prints the code size. Exits 77 (the test's SKIP_RETURN_CODE), saying why, when the
#       cross compiler is not installed.
#   c_runtime_compile.sh headers TARGET SOURCE_DIR WORK_DIR CC IMUFIT CALIBRATION...
#       the header `imufit export --format c` writes for each calibration (real fitted units),
#       included with the runtime and both initializers used (_INITIALIZER in the double build,
#       _INITIALIZER_F in the float build), compiled as strict C99 with -Wconversion
#       -Wdouble-promotion -Werror: TARGET host with CC, or cortex-m4 with arm-none-eabi-gcc
#       (exit 77, saying so, when it is not installed).
set -euo pipefail
mode=$1
target=
if [[ $mode == headers ]]; then
  target=$2
  shift
fi
source_dir=$2 work_dir=$3
runtime=$source_dir/model/c/imufit_runtime.c
strict=(-std=c99 -Wall -Wextra -Werror -pedantic -Wdouble-promotion -Wconversion -I"$source_dir/model/c")

if [[ $mode == strict ]]; then
  cc=$4
  mkdir -p "$work_dir"
  "$cc" "${strict[@]}" -c "$runtime" -o "$work_dir/runtime_double.o"
  "$cc" "${strict[@]}" -DIMUFIT_RUNTIME_FLOAT -c "$runtime" -o "$work_dir/runtime_float.o"
  echo "imufit_runtime.c compiles as strict C99, double and float builds: $cc ${strict[*]}"
  exit 0
fi

cortex_m4=(-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -Os)

require_cross_compiler() {
  for tool in "$@"; do
    if ! command -v "$tool" >/dev/null 2>&1; then
      echo "SKIPPED: $tool is not installed (Debian: gcc-arm-none-eabi libnewlib-arm-none-eabi, among" \
           "scripts/lib.sh's packages): the Cortex-M4F build is not checked"
      exit 77
    fi
  done
}

if [[ $mode == headers ]]; then
  cc=$4 imufit=$5
  shift 5
  if [[ $target == cortex-m4 ]]; then
    require_cross_compiler arm-none-eabi-gcc
    cc=arm-none-eabi-gcc
    flags=("${strict[@]}" "${cortex_m4[@]}")
  else
    flags=("${strict[@]}")
  fi
  mkdir -p "$work_dir"
  for calibration in "$@"; do
    unit=$(basename "$calibration" .yaml)
    "$imufit" export -q -c "$calibration" -f c --c-name "$unit" -o "$work_dir/$unit.h" --max-loss 1,1
    upper=$(echo "$unit" | tr '[:lower:]' '[:upper:]')
    cat >"$work_dir/${unit}_use.c" <<EOF
#include "imufit_runtime.h"
#define IMUFIT_RUNTIME_FLOAT
#include "imufit_runtime.h" /* both builds' declarations */
#include "$unit.h"
const imufit_calibration ${unit}_double = ${upper}_INITIALIZER;
const imufit_calibration_f ${unit}_float = ${upper}_INITIALIZER_F;
EOF
    "$cc" "${flags[@]}" -I"$work_dir" -c "$work_dir/${unit}_use.c" -o "$work_dir/${unit}_use_$target.o"
    echo "$unit.h (imufit export --format c of $calibration) compiles, double and float builds: $cc ${flags[*]}"
  done
  exit 0
fi

require_cross_compiler arm-none-eabi-gcc arm-none-eabi-nm arm-none-eabi-size
mkdir -p "$work_dir"
object=$work_dir/runtime_cortex_m4.o
arm-none-eabi-gcc "${strict[@]}" -DIMUFIT_RUNTIME_FLOAT "${cortex_m4[@]}" -c "$runtime" -o "$object"
undefined=$(arm-none-eabi-nm -u "$object" | awk '{print $NF}')
if [[ -n $undefined ]]; then
  echo "the Cortex-M4F float build calls routines it must not (double-precision helpers, libm, libc):"
  echo "$undefined"
  exit 1
fi
text=$(arm-none-eabi-size "$object" | awk 'NR == 2 {print $1}')
echo "Cortex-M4F float build (-Os): no undefined symbol (no __aeabi_d*, no double libm, no libc);" \
     "code size $text bytes of .text"
arm-none-eabi-size "$object"
