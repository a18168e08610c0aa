#!/bin/sh
# SPDX-License-Identifier: MIT
# poses_touch_cli.sh - issue 50: `rcal poses` for plate touches from the
# command line. Bad plate options are refused (exit 2) with what and where
# (the option's occurrence, the plate's number, the character); a good plan
# writes a touch file's skeleton (pose,plane,q1..q6,height_mm) that
# `rcal calibrate` reads as a touch file (its header), and --json is one
# JSON object (python3's json module, when python3 is present).
#
# Usage: tests/tools/poses_touch_cli.sh BUILD_DIR
set -u
src=$(cd "$(dirname "$0")/../.." && pwd)
rcal=$(cd "$1" && pwd)/tools/rcal
robot=$src/data/irb120.json
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
P0=375,0,60,0,0,1,140
P1=465,0,375,-1,0,0,140
P2=390,0,210,-0.64,0,0.77,140
refused() { # refused 'expected text' args...
    want=$1
    shift
    "$rcal" poses --robot "$robot" --count 30 --out "$work/bad.csv" --tool 10,-5,150 "$@" > "$work/out" 2> "$work/err"
    rc=$?
    if [ $rc -ne 2 ] || ! grep -qF -- "$want" "$work/err" || [ -e "$work/bad.csv" ]; then
        echo "FAIL: $* -> exit $rc, expected 2 with '$want'; stderr:"; cat "$work/err"; fail=1
    else
        echo "ok   refused: $(cat "$work/err")"
    fi
}
refused "--plate 2 '1,2,3' (plate 1), at character" --plate $P0 --plate 1,2,3 --plate $P2
refused "--plate 3 '390,0,210,0,0,0' (plate 2): the normal" --plate $P0 --plate $P1 --plate 390,0,210,0,0,0
refused "--plate 1 '375,0,60,0,0,1,x' (plate 0), at character 16" --plate 375,0,60,0,0,1,x
refused "--gauge-plate 4: only 3 --plate given" --plate $P0 --plate $P1 --plate $P2 --gauge-mm 50 --gauge-plate 4
refused "give its --gauge-mm" --plate $P0 --plate $P1 --plate $P2 --gauge-plate 1
refused "--sensor cable takes no --plate" --sensor cable --plate $P0
refused "(plate 1): size 15 mm" --plate $P0 --plate 465,0,375,-1,0,0,15 --plate $P2
refused "--plate is required" --sensor=touch
refused "(plate 0): the normal" --plate=1,2,3,0,0,0
# a good plan: the skeleton, read back by calibrate's touch reader (rows valid: joints within limits, plates)
"$rcal" poses --robot "$robot" --count 30 --candidates 800 --out "$work/plan.csv" --tool 10,-5,150 --plate $P0 \
    --plate $P1 --plate $P2 --gauge-mm 50 --gauge-at 375,30,60 --json > "$work/plan.json" 2> "$work/err" || {
    echo "FAIL: the plan: $(cat "$work/err")"; exit 1; }
head -1 "$work/plan.csv" | grep -qx 'pose,plane,q1,q2,q3,q4,q5,q6,height_mm' || { echo "FAIL: header"; fail=1; }
[ "$(tail -n +2 "$work/plan.csv" | wc -l)" -eq 30 ] || { echo "FAIL: 30 rows"; fail=1; }
if command -v python3 > /dev/null; then
    python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["sensor"]=="touch" and d["rows"]==30, d' \
        "$work/plan.json" || { echo "FAIL: --json"; fail=1; }
fi
# the skeleton is a touch file: calibrate reads it by its header (plane column) and fits
"$rcal" calibrate --robot "$robot" --data "$work/plan.csv" --out "$work/model.json" --test-fraction 0 \
    > "$work/cal" 2>&1 || { echo "FAIL: calibrate on the skeleton:"; tail -5 "$work/cal"; fail=1; }
[ $fail -eq 0 ] && echo "all ok"
exit $fail
