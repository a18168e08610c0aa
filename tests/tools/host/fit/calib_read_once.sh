#!/bin/bash
# SPDX-License-Identifier: MIT
# calib_read_once.sh - issue 50: a calibration opens each input once (the
# robot file, every --data, --validate and --positions file; the command
# reads nothing the host reads again). Runs `rcal calibrate` under strace
# and counts the openat calls of each input, which must be exactly 1; the
# run must succeed (a run cut short would open less). Exit 77 (skipped)
# without strace.
#
# Usage: tests/tools/host/fit/calib_read_once.sh BUILD_DIR
set -u
src=$(cd "$(dirname "$0")/../../../.." && pwd)
rcal=$(cd "$1" && pwd)/tools/rcal
command -v strace > /dev/null || { echo "strace absent: skipped"; exit 77; }
[ -x "$rcal" ] || { echo "$rcal missing"; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
cp "$src/data/sim_irb120.csv" data.csv
cp "$src/data/sim_irb120.csv" val.csv
cp "$src/data/irb120.json" robot.json
# tracker positions of the simulated truth (as scripts/golden_check.sh makes them): the truth's flange seen
# by a tracker turned 90 deg about z
awk '/"encoder_mm"/ { sub(/,[ \t]*$/, ""); print; print "}"; exit } { print }' "$src/data/sim_irb120_truth.json" \
    > truth_robot.json
"$rcal" simulate --robot truth_robot.json --err-len-mm 0 --err-ang-deg 0 --q-step-deg 0.001 --out sim.csv \
    --samples 60 --seed 7 > /dev/null || { echo "simulate failed"; exit 1; }
awk -F, 'NR == 1 { print "q1,q2,q3,q4,q5,q6,x,y,z"; next }
    { printf "%s,%s,%s,%s,%s,%s,%.4f,%.4f,%.4f\n", $4, $5, $6, $7, $8, $9, 1500 - $2, $1 + 300, $3 - 200 }' \
    sim.csv > pos.csv
fail=0
# run NAME FILES -- ARGS: rcal calibrate ARGS under strace; each of FILES opened exactly once
check() {
    local name=$1 files=$2
    shift 2
    # LeakSanitizer cannot run under ptrace (an ASan build aborts at exit): leaks are the sanitizer ctest's
    # other tests' to find, this one counts opens
    ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" \
        strace -f -o "trace_$name" -e trace=openat "$rcal" calibrate "$@" > "out_$name" 2> "err_$name"
    local rc=$?
    if [ $rc -ne 0 ]; then
        echo "FAIL $name: rcal calibrate exited $rc"; cat "err_$name"; fail=1; return
    fi
    for f in $files; do
        local n
        n=$(grep -v ENOENT "trace_$name" | grep -c "\"$f\"")
        if [ "$n" -ne 1 ]; then
            echo "FAIL $name: $f opened $n times (want 1)"; grep "\"$f\"" "trace_$name"; fail=1
        else
            echo "ok   $name: $f opened once"
        fi
    done
}
check all "robot.json data.csv val.csv pos.csv" --robot robot.json --data data.csv --validate val.csv \
    --positions pos.csv --out model.json --plots plots
check residuals "robot.json data.csv val.csv" --robot robot.json --data data.csv --validate val.csv \
    --residuals res.csv --out model2.json --json
exit $fail
