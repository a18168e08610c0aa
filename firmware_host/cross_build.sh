#!/bin/sh
# SPDX-License-Identifier: MIT
# cross_build.sh - the rcal core and the firmware example for two
# microcontrollers, warnings as errors, with size reports and symbol checks:
#   m7   Cortex-M7 with double-precision FPU (fpv5-d16), rc_real = double
#   m4f  Cortex-M4F with single-precision FPU (fpv4-sp-d16), rc_real = float
#        (-DRC_REAL_FLOAT): the compensation path (rc_kin.o, rc_comp.o,
#        fw_example.o) and the linked example must not call a double routine
#        (no __aeabi_d*, __aeabi_f2d, ..., no double libm function such as
#        sin or sqrt: on this FPU each is a soft-float library call).
# Both: nothing of the heap, stdio or assert linked.
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

WARN="-std=c99 -Wall -Wextra -Werror -pedantic -Wconversion -Wdouble-promotion -Wsign-conversion -Wshadow -Wundef -Wmissing-prototypes -Wstrict-prototypes"
OPT="-Os -ffunction-sections -fdata-sections"
# Contract checks go to the firmware's fault handler (fw_port.h), not to
# assert(), which would link fprintf; fw_port.h also leaves the models out of
# the stream (RC_COMP_STREAM_OWN_MODELS=0: they are tables in flash).
PORT="-include $ROOT/firmware_host/fw_port.h -I$ROOT/lib -I$OUT/include -I$ROOT/firmware_host"
# The compensation path's objects (what a firmware links for compensation).
COMP_OBJS="rc_kin.o rc_comp.o fw_example.o"
FORBIDDEN='^_?(malloc|calloc|realloc|free|_malloc_r|_free_r|_sbrk|_sbrk_r|sbrk|printf|fprintf|sprintf|snprintf|vfprintf|_vfprintf_r|_svfprintf_r|iprintf|fiprintf|puts|fputs|fwrite|_fwrite_r|fopen|__assert_func)$'
# Double-precision routines: the soft-float ABI helpers and libm's double functions.
DOUBLE_SYMS='^(__aeabi_d[a-z0-9]*|__aeabi_f2d|__aeabi_[iu]l?2d|__aeabi_l2d|__aeabi_ul2d|__(add|sub|mul|div|neg|extendsf|truncdf|fix|float|fixuns|floatun|eq|ne|lt|le|gt|ge|unord)[a-z]*df[0-9a-z]*|sin|cos|tan|sqrt|atan2|atan|asin|acos|fabs|fmax|fmin|exp|log|pow|fmod|sincos|hypot|floor|ceil|round)$'

rm -rf "$OUT"
mkdir -p "$OUT/obj"
# rc_version.h: version and compile-time limits (RC_MAX_PARAMS ...)
cmake -DRCAL_HEADER_DIR="$OUT/include" -P "$ROOT/cmake/rcal_version_header.cmake"
echo "cross_build: $("$CC" --version | head -n 1)"
rc_all=0

build() { # name "arch flags" "extra defines"
    name=$1 arch=$2 defs=$3
    dir="$OUT/$name"
    mkdir -p "$dir/obj"
    echo
    echo "== $name: $arch $defs $OPT"
    objs=""
    for src in "$ROOT"/lib/*.c; do
        o="$dir/obj/$(basename "$src" .c).o"
        "$CC" $arch $WARN $OPT $defs $PORT -c "$src" -o "$o"
        objs="$objs $o"
    done
    "$AR" rcs "$dir/librcalcore.a" $objs
    "$CC" $arch $WARN $OPT $defs $PORT -DFW_EXAMPLE_MAIN -c "$ROOT/firmware_host/fw_example.c" -o "$dir/obj/fw_example.o"
    # Link: newlib-nano with the nosys stubs for the start-up code; unused
    # sections dropped; the map file shows what came from where.
    "$CC" $arch $OPT --specs=nano.specs --specs=nosys.specs -Wl,--gc-sections -Wl,-Map="$dir/fw_example.map" \
        "$dir/obj/fw_example.o" "$dir/librcalcore.a" -lm -o "$dir/fw_example.elf"

    echo "core objects (text = code + const data, data = initialised RAM, bss = zeroed RAM; bytes):"
    "$SIZE" -t $objs | sed "s|$dir/obj/||"
    echo
    echo "compensation path objects:"
    (cd "$dir/obj" && "$SIZE" -t $COMP_OBJS)
    echo
    echo "compensation path as linked (fw_example.elf: crt0, libm and libc start-up included):"
    "$SIZE" "$dir/fw_example.elf"
    echo
    echo "largest symbols of the compensation path:"
    "$NM" --size-sort -S -C "$dir/fw_example.elf" | tail -n 8

    bad=$("$NM" "$dir/fw_example.elf" | awk '{print $NF}' | grep -E "$FORBIDDEN" || true)
    if [ -n "$bad" ]; then
        echo "cross_build: $name: FAIL: heap or stdio linked into the firmware example:" >&2
        echo "$bad" >&2
        rc_all=1
    else
        echo "cross_build: $name: ok: no malloc/free/sbrk/printf/stdio/assert symbols in fw_example.elf"
    fi
}

# nm of the compensation objects (undefined references) and of the linked
# example (everything): no double routine. $1 = build name.
check_no_double() {
    dir="$OUT/$1"
    used=$(cd "$dir/obj" && "$NM" -u $COMP_OBJS | awk '{print $NF}' | grep -E "$DOUBLE_SYMS" | sort -u || true)
    linked=$("$NM" "$dir/fw_example.elf" | awk '{print $NF}' | grep -E "$DOUBLE_SYMS" | sort -u || true)
    n_used=$(printf '%s' "$used" | grep -c . || true)
    n_linked=$(printf '%s' "$linked" | grep -c . || true)
    echo "cross_build: $1: double routines called by the compensation objects: $n_used; linked into fw_example.elf: $n_linked"
    if [ -n "$used$linked" ]; then
        echo "cross_build: $1: FAIL: soft-float double on the single-precision compensation path:" >&2
        printf '%s\n%s\n' "$used" "$linked" | sort -u | sed '/^$/d' >&2
        rc_all=1
    fi
}

build m7 "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb" ""
build m4f "-mcpu=cortex-m4 -mfpu=fpv4-sp-d16 -mfloat-abi=hard -mthumb" "-DRC_REAL_FLOAT"
echo
check_no_double m4f
echo
m4f_text=$("$SIZE" "$OUT/m4f/fw_example.elf" | awk 'NR == 2 {print $1 " B text, " $2 " B data, " $3 " B bss"}')
m7_text=$("$SIZE" "$OUT/m7/fw_example.elf" | awk 'NR == 2 {print $1 " B text, " $2 " B data, " $3 " B bss"}')
echo "cross_build: fw_example.elf Cortex-M7 (double): $m7_text"
echo "cross_build: fw_example.elf Cortex-M4F (float): $m4f_text"
[ $rc_all -eq 0 ] && echo "cross_build: ok"
exit $rc_all
