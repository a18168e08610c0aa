#!/bin/bash
# SPDX-License-Identifier: MIT
# diag_read_once.sh - issue 50 for `rcal diagnose`: each input (the robot
# file, every --data and --positions file, a touch file) opened exactly
# once, whatever the options; the later stages (the jumps' calibration, the
# next step's model for --out, --report's calibration and page, --residuals)
# take the inputs the diagnosis read (rch_diagnose_result.raw), and the
# outputs are only written (their temporary file, once, O_CREAT), never read
# back. Runs `rcal diagnose` under strace and counts the openat calls; the
# run must succeed (a run cut short would open less). Exit 77 (skipped)
# without strace.
#
# Usage: tests/tools/host/studies/diag_read_once.sh BUILD_DIR
set -u
src=$(cd "$(dirname "$0")/../../../.." && pwd)
rcal=$(cd "$1" && pwd)/tools/rcal
command -v strace > /dev/null || { echo "strace absent: skipped"; exit 77; }
[ -x "$rcal" ] || { echo "$rcal missing"; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
cp "$src/data/sim_irb120.csv" data.csv
cp "$src/data/irb120.json" robot.json
cp "$src/fuzz/corpus/fuzz_touch/touches.csv" touch.csv
head -301 "$src/data/sim_irb120.csv" > part1.csv
{ head -1 "$src/data/sim_irb120.csv"; tail -n +302 "$src/data/sim_irb120.csv"; } > part2.csv
# tracker positions of the simulated truth (as calib_read_once.sh makes them)
awk '/"encoder_mm"/ { sub(/,[ \t]*$/, ""); print; print "}"; exit } { print }' "$src/data/sim_irb120_truth.json" \
    > truth_robot.json
"$rcal" simulate --robot truth_robot.json --err-len-mm 0 --err-ang-deg 0 --q-step-deg 0.001 --out sim.csv \
    --samples 60 --seed 7 > /dev/null || { echo "simulate failed"; exit 1; }
awk -F, 'NR == 1 { print "q1,q2,q3,q4,q5,q6,x,y,z"; next }
    { printf "%s,%s,%s,%s,%s,%s,%.4f,%.4f,%.4f\n", $4, $5, $6, $7, $8, $9, 1500 - $2, $1 + 300, $3 - 200 }' \
    sim.csv > pos.csv
fail=0
# check NAME FILES ARGS...: rcal diagnose ARGS under strace; each of FILES opened exactly once
check() {
    local name=$1 files=$2
    shift 2
    # LeakSanitizer cannot run under ptrace (an ASan build aborts at exit)
    ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" \
        strace -f -o "trace_$name" -e trace=openat "$rcal" diagnose "$@" > "out_$name" 2> "err_$name"
    local rc=$?
    if [ $rc -ne 0 ]; then
        echo "FAIL $name: rcal diagnose exited $rc"; cat "err_$name"; fail=1; return
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
# written NAME FILES: each of FILES (outputs) never opened by its own name and its temporary opened once, created
written() {
    local name=$1 files=$2 f n t
    for f in $files; do
        n=$(grep -v ENOENT "trace_$name" | grep -c "\"$f\"")
        t=$(grep -v ENOENT "trace_$name" | grep "\"$f\.tmp" | grep -c O_CREAT)
        if [ "$n" -ne 0 ] || [ "$t" -ne 1 ]; then
            echo "FAIL $name: output $f opened $n times by its name (want 0: never read back), its temporary $t" \
                "times (want 1)"; grep "\"$f" "trace_$name"; fail=1
        elif [ ! -s "$f" ]; then
            echo "FAIL $name: output $f not written"; fail=1
        else
            echo "ok   $name: $f only written"
        fi
    done
}
check one "robot.json data.csv" --robot robot.json --data data.csv
check files_positions "robot.json part1.csv part2.csv pos.csv" --robot robot.json --data part1.csv --data part2.csv \
    --positions pos.csv --plots plots --out m2.json
written files_positions "m2.json"
# --report (its calibration and page from the inputs read), the next step's model, --residuals, --json
check report "robot.json data.csv" --robot robot.json --data data.csv --report r.html --out m.json --json \
    --residuals res.csv
written report "r.html r.calibration.json r.diagnosis.json m.json res.csv"
grep -q '"format":"rcal-diagnose/1"' out_report || { echo "FAIL report: no JSON on stdout"; fail=1; }
# a touch file (another sensor) with a cable file, and the next step's model
check touch "robot.json touch.csv part1.csv" --robot robot.json --data touch.csv --data part1.csv --out m3.json
written touch "m3.json"
# the real IRB120 file (when present): its --report calibration keeps a refit (a length offset or a drift),
# which used to drop the poses read and read the file again for the page
real="$src/../shared/data/robotcali.csv"
if [ -f "$real" ]; then
    cp "$real" real.csv
    check real "robot.json real.csv" --robot robot.json --data real.csv --dequantize-joints --report r5.html \
        --out m5.json
    written real "r5.html m5.json"
else
    echo "skip real: $real absent"
fi
exit $fail
