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
set -euo pipefail
mode=$1 source_dir=$2 work_dir=$3
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

for tool in arm-none-eabi-gcc arm-none-eabi-nm arm-none-eabi-size; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIPPED: $tool is not installed (Debian: gcc-arm-none-eabi libnewlib-arm-none-eabi, among" \
         "scripts/lib.sh's packages): the Cortex-M4F build of the C runtime is not checked"
    exit 77
  fi
done
mkdir -p "$work_dir"
object=$work_dir/runtime_cortex_m4.o
arm-none-eabi-gcc "${strict[@]}" -DIMUFIT_RUNTIME_FLOAT -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 \
  -mfloat-abi=hard -Os -c "$runtime" -o "$object"
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
