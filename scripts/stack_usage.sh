#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# scripts/stack_usage.sh - stack use of the core's public functions (issue 7).
#
# Compiles lib/rc_*.c with gcc -fstack-usage -fcallgraph-info=su and prints,
# per public (non-static) function, its own frame and the worst case with
# every core function it can call (the call graph gcc wrote; calls into libc
# and libm count 0, recursion and calls through pointers are flagged), largest
# first. Done for the host (x86-64, -O2) and, when arm-none-eabi-gcc is
# installed, for the firmware target (Cortex-M7, -Os, as
# firmware_host/cross_build.sh builds it).
#
#   scripts/stack_usage.sh [--target host|arm]... [--limit FUNC=BYTES]... [--out DIR]
#
# --limit FUNC=BYTES fails (exit 1) when FUNC's worst case exceeds BYTES on a
# target analysed, or when FUNC is not found; repeatable. The test run uses
# `--target arm --limit rc_comp_stream_step=2048` (ctest comp_stack_m7).
# Without arm-none-eabi-gcc an arm run with limits exits 77 (skipped).
#
# Environment (the options override it): OUT (default <repo>/build-stack),
# TOP (rows shown, default all), STACK_TARGETS (default "host arm"),
# STACK_LIMIT (fail when any public function's worst case exceeds this many
# bytes; default none).
set -u -o pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
OUT=${OUT:-$ROOT/build-stack}
TOP=${TOP:-0}
TARGETS=${STACK_TARGETS:-host arm}
LIMIT=${STACK_LIMIT:-0}
FLIMITS=""
opt_targets=""
while [ $# -gt 0 ]; do
    case $1 in
    --target) [ $# -ge 2 ] || { echo "stack_usage: --target needs host or arm" >&2; exit 2; }
        case $2 in host|arm) ;; *) echo "stack_usage: --target must be host or arm, not '$2'" >&2; exit 2 ;; esac
        opt_targets="$opt_targets $2"; shift 2 ;;
    --limit) [ $# -ge 2 ] || { echo "stack_usage: --limit needs FUNC=BYTES" >&2; exit 2; }
        if ! [[ $2 =~ ^[A-Za-z_][A-Za-z0-9_]*=[1-9][0-9]{0,8}$ ]]; then
            echo "stack_usage: --limit must be FUNC=BYTES (a C name, 1..999999999), not '$2'" >&2; exit 2
        fi
        FLIMITS="$FLIMITS $2"; shift 2 ;;
    --out) [ $# -ge 2 ] || { echo "stack_usage: --out needs a directory" >&2; exit 2; }
        OUT=$2; shift 2 ;;
    -h|--help) sed -n '2,/^set -u/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "stack_usage: unknown argument '$1' (see --help)" >&2; exit 2 ;;
    esac
done
[ -n "$opt_targets" ] && TARGETS=$opt_targets
WARN="-std=c99 -Wall -Wextra -pedantic"
rc_all=0

analyse() { # label dir
    python3 - "$1" "$2" "$TOP" "$LIMIT" "$FLIMITS" <<'EOF'
import glob, os, re, sys

label, d, top, limit = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
flimits = [(f, int(b)) for f, b in (x.split("=") for x in sys.argv[5].split())]
own, qual, name_of, edges, defined = {}, {}, {}, {}, set()
node_re = re.compile(r'node: \{ title: "([^"]+)" label: "([^\\"]+)\\n([^\\"]+)(?:\\n(\d+) bytes \(([^)]*)\))?"')
edge_re = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')
for ci in glob.glob(os.path.join(d, "*.ci")):
    for line in open(ci):
        m = node_re.search(line)
        if m:
            title, name, loc, nbytes, q = m.groups()
            name_of[title] = name
            if nbytes is not None:
                own[title] = int(nbytes)
                qual[title] = q
                defined.add(title)
            continue
        m = edge_re.search(line)
        if m:
            edges.setdefault(m.group(1), []).append(m.group(2))

memo, flags = {}, {}
def worst(t, stack=()):
    if t not in defined:
        return 0, set()          # libc/libm/builtins: not counted
    if t in stack:
        return 0, {"recursion"}
    if t in memo:
        return memo[t]
    best, fl = 0, set()
    if "dynamic" in qual[t] and "bounded" not in qual[t]:
        fl.add("unbounded frame")
    for c in edges.get(t, []):
        if c == "__indirect_call":
            fl.add("indirect call")
            continue
        w, f = worst(c, stack + (t,))
        fl |= f
        best = max(best, w)
    memo[t] = (own[t] + best, fl)
    return memo[t]

# public = defined with external linkage (gcc titles static functions "file:name")
public = [t for t in defined if ":" not in t]
rows = sorted(((worst(t)[0], own[t], t, qual[t], ",".join(sorted(worst(t)[1]))) for t in public),
              key=lambda r: (-r[0], -r[1], r[2]))
print(f"{label}: {len(public)} public functions of lib/ (bytes; worst case = own frame + deepest chain of core callees)")
print(f"  {'function':<28} {'own':>7} {'worst':>7}  {'gcc':<16} notes")
for w, o, t, q, fl in (rows[:top] if top > 0 else rows):
    print(f"  {t:<28} {o:>7} {w:>7}  {q:<16} {fl}")
bad = 0
over = [r for r in rows if limit > 0 and r[0] > limit]
if over:
    print(f"{label}: {len(over)} function(s) above STACK_LIMIT={limit} bytes")
    bad = 1
for f, b in flimits:
    if f not in defined:
        print(f"{label}: limit {f}={b}: FAIL: no such function in lib/")
        bad = 1
        continue
    w, fl = worst(f)
    ok = w <= b and not fl
    why = "" if not fl else f" (worst case not bounded: {','.join(sorted(fl))})"
    print(f"{label}: limit {f}: worst case {w} B {'<=' if w <= b else '>'} {b} B: {'ok' if ok else 'FAIL'}{why}")
    bad |= 0 if ok else 1
sys.exit(bad)
EOF
}

build() { # label cc flags...
    local label=$1 cc=$2
    shift 2
    local dir="$OUT/$label"
    rm -rf "$dir"
    mkdir -p "$dir"
    cmake -DRCAL_HEADER_DIR="$dir/include" -P "$ROOT/cmake/rcal_version_header.cmake" || return 1
    for f in "$ROOT"/lib/rc_*.c; do
        b=$(basename "$f" .c)
        if ! (cd "$dir" && "$cc" $WARN "$@" -I"$ROOT/lib" -I"$dir/include" -fstack-usage -fcallgraph-info=su -c "$f" -o "$b.o"); then
            echo "stack_usage: $label: compile of $f failed"
            return 1
        fi
    done
}

for t in $TARGETS; do
    case $t in
    host)
        build host "${CC:-gcc}" -O2 -DRC_MAX_PARAMS=96 || { rc_all=1; continue; }
        analyse "host x86-64 gcc -O2" "$OUT/host" || rc_all=1
        ;;
    arm)
        if ! command -v arm-none-eabi-gcc >/dev/null; then
            echo "stack_usage: arm-none-eabi-gcc not installed, Cortex-M7 figures skipped"
            [ -n "$FLIMITS" ] && exit 77
            continue
        fi
        port=()
        [ -f "$ROOT/firmware_host/fw_port.h" ] && port=(-include "$ROOT/firmware_host/fw_port.h" -I"$ROOT/firmware_host")
        build arm arm-none-eabi-gcc -mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb -Os \
            -ffunction-sections -fdata-sections -DRC_MAX_PARAMS=96 "${port[@]}" || { rc_all=1; continue; }
        echo
        analyse "Cortex-M7 arm-none-eabi-gcc -Os" "$OUT/arm" || rc_all=1
        ;;
    esac
done
exit $rc_all
