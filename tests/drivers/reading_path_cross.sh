#!/bin/sh
# SPDX-License-Identifier: MIT
# reading_path_cross.sh - the reading path builds for a microcontroller.
#
# Compiles the portable half of the data path (drivers/rcd_proto.c,
# rcd_display.c, rcd_port.c, rcd_mock.c: serial byte -> reading; and
# lib/rc_stable.c: reading -> sample) for a Cortex-M7 with the core's warning
# set, and checks that the objects need nothing from an OS: the only
# undefined symbols allowed are the compiler's memory helpers. In particular
# no clock_gettime: time comes through the port's function table.
# Exit 77 (skipped) without arm-none-eabi-gcc.
# Usage: reading_path_cross.sh SOURCE_DIR WORK_DIR
set -eu
src=$1
work=$2
command -v arm-none-eabi-gcc >/dev/null 2>&1 || { echo "arm-none-eabi-gcc not found: skipped"; exit 77; }
mkdir -p "$work"
flags="-std=c99 -mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb -Os -ffreestanding
 -Wall -Wextra -Werror -pedantic -Wconversion -Wdouble-promotion -Wsign-conversion -Wundef
 -I$src/lib -I$src/drivers -DRC_MAX_PARAMS=64"
for f in drivers/rcd_proto.c drivers/rcd_display.c drivers/rcd_port.c drivers/rcd_mock.c lib/rc_stable.c \
         lib/rc_status.c; do
    o="$work/$(basename "$f" .c).o"
    # shellcheck disable=SC2086
    arm-none-eabi-gcc $flags -c "$src/$f" -o "$o"
done
defined=$(arm-none-eabi-nm --defined-only "$work"/*.o | awk 'NF == 3 {print $3}' | sort -u)
undef=$(arm-none-eabi-nm -u "$work"/*.o | awk 'NF == 2 {print $2}' | sort -u | grep -v -x -F "$defined" || true)
bad=$(printf '%s\n' "$undef" | grep -v -E '^(memcpy|memmove|memset|memcmp|memchr|__aeabi_[a-z0-9_]+)?$' || true)
size=$(arm-none-eabi-size -t "$work"/*.o | awk 'END {print $1 + $2}')
echo "reading path for Cortex-M7: $(ls "$work"/*.o | wc -l) objects, $size bytes of code and data"
echo "undefined symbols: $(printf '%s ' $undef)"
if [ -n "$bad" ]; then
    echo "FAIL: the reading path needs OS or libc functions: $bad"
    exit 1
fi
echo "OK: no OS call (no clock_gettime, no stdio) on the reading path"
