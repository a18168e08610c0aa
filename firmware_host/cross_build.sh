#!/bin/sh
# cross_build.sh - the rcal core and the firmware example for a Cortex-M7
# with double-precision FPU, warnings as errors, then the size report and the
# check that nothing of the heap or stdio is linked.
#
#   firmware_host/cross_build.sh [OUTDIR]        (default: build-arm in the repo)
#
# Needs Debian's gcc-arm-none-eabi and libnewlib-arm-none-eabi (math.h,
# string.h, libm). Exit status: 0 ok, 1 compile/link failure or a forbidden
# symbol, 2 toolchain missing.
set -eu
ROOT=$(cd "$(dirname "$0")/.." && pwd)
OUT=${1:-"$ROOT/build-arm"}
CC=${ARM_CC:-arm-none-eabi-gcc}
PREFIX=${CC%gcc}
AR=${PREFIX}ar
SIZE=${PREFIX}size
NM=${PREFIX}nm

if ! command -v "$CC" >/dev/null 2>&1; then
    echo "cross_build: $CC not found (apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi)" >&2
    exit 2
fi
if ! echo '#include <math.h>
#include <string.h>' | "$CC" -mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -x c -fsyntax-only - 2>/dev/null; then
    echo "cross_build: newlib headers missing (apt-get install libnewlib-arm-none-eabi)" >&2
    exit 2
fi

ARCH="-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb"
WARN="-std=c99 -Wall -Wextra -Werror -pedantic -Wconversion -Wdouble-promotion -Wsign-conversion -Wshadow -Wundef -Wmissing-prototypes -Wstrict-prototypes"
OPT="-Os -ffunction-sections -fdata-sections"
# Contract checks go to the firmware's fault handler (fw_port.h), not to
# assert(), which would link fprintf.
PORT="-include $ROOT/firmware_host/fw_port.h -I$ROOT/lib -I$OUT/include -I$ROOT/firmware_host"

rm -rf "$OUT"
mkdir -p "$OUT/obj"
# rc_version.h: version and compile-time limits (RC_MAX_PARAMS ...)
cmake -DRCAL_HEADER_DIR="$OUT/include" -P "$ROOT/cmake/rcal_version_header.cmake"
echo "cross_build: $("$CC" --version | head -n 1)"
echo "cross_build: flags $ARCH $WARN $OPT"
objs=""
for src in "$ROOT"/lib/*.c; do
    o="$OUT/obj/$(basename "$src" .c).o"
    "$CC" $ARCH $WARN $OPT $PORT -c "$src" -o "$o"
    objs="$objs $o"
done
"$AR" rcs "$OUT/librcalcore.a" $objs
"$CC" $ARCH $WARN $OPT $PORT -DFW_EXAMPLE_MAIN -c "$ROOT/firmware_host/fw_example.c" -o "$OUT/obj/fw_example.o"
# Link: newlib-nano with the nosys stubs for the start-up code; unused
# sections dropped; the map file shows what came from where.
"$CC" $ARCH $OPT --specs=nano.specs --specs=nosys.specs -Wl,--gc-sections -Wl,-Map="$OUT/fw_example.map" \
    "$OUT/obj/fw_example.o" "$OUT/librcalcore.a" -lm -o "$OUT/fw_example.elf"

echo
echo "core objects (text = code + const data, data = initialised RAM, bss = zeroed RAM; bytes):"
"$SIZE" -t $objs | sed "s|$OUT/obj/||"
echo
echo "compensation path as linked (fw_example.elf: crt0, libm and libc start-up included):"
"$SIZE" "$OUT/fw_example.elf"
echo
echo "largest symbols of the compensation path:"
"$NM" --size-sort -S -C "$OUT/fw_example.elf" | tail -n 12

bad=$("$NM" "$OUT/fw_example.elf" | awk '{print $NF}' |
      grep -E '^_?(malloc|calloc|realloc|free|_malloc_r|_free_r|_sbrk|_sbrk_r|sbrk|printf|fprintf|sprintf|snprintf|vfprintf|_vfprintf_r|_svfprintf_r|iprintf|fiprintf|puts|fputs|fwrite|_fwrite_r|fopen|__assert_func)$' || true)
if [ -n "$bad" ]; then
    echo "cross_build: FAIL: heap or stdio linked into the firmware example:" >&2
    echo "$bad" >&2
    exit 1
fi
echo
echo "cross_build: ok: no malloc/free/sbrk/printf/stdio/assert symbols in fw_example.elf"
