#!/bin/bash
# SPDX-License-Identifier: MIT
# calib_read_once.sh - issue 50: a calibration opens each input once (the
# robot file, every --data, --validate and --positions file; the command
# reads nothing the host reads again). Runs `rcal calibrate` under strace
# and counts the openat calls of each input, which must be exactly 1; the
# run must succeed (a run cut short would open less). With --report (the
# page drawn from the run's results, samples and model in memory) also:
# the model written and the report's calibration JSON are opened only to be
# written (their temporary file, once, O_CREAT), never read back, and the
# page was written. Exit 77 (skipped) without strace.
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
cp "$src/fuzz/corpus/fuzz_touch/touches.csv" touch.csv
head -301 "$src/data/sim_irb120.csv" > part1.csv
{ head -1 "$src/data/sim_irb120.csv"; tail -n +302 "$src/data/sim_irb120.csv"; } > part2.csv
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
# written NAME FILES: each of FILES (outputs) never opened by its own name (read back) and its temporary
# file opened once, to be created
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
# --report with every other output option: the page from the run in memory
check report "robot.json data.csv val.csv pos.csv" --robot robot.json --data data.csv --validate val.csv \
    --positions pos.csv --out rmodel.json --plots rplots --report r.html
written report "rmodel.json r.calibration.json r.html"
check report_files "robot.json part1.csv part2.csv val.csv" --robot robot.json --data part1.csv --data part2.csv \
    --validate val.csv --residuals rres.csv --out rmodel2.json --report r2.html --json
written report_files "rmodel2.json r2.calibration.json r2.html rres.csv"
# a touch file (another sensor: its rows give the page no pose) with a cable file
check report_touch "robot.json touch.csv part1.csv" --robot robot.json --data touch.csv --data part1.csv \
    --out rmodel3.json --report r3.html
written report_touch "rmodel3.json r3.calibration.json r3.html"
# without --out: no model, the page still from memory
check report_nomodel "robot.json data.csv" --robot robot.json --data data.csv --report r4.html
written report_nomodel "r4.calibration.json r4.html"
# the model on stdout (--out -): the page takes its text from memory (it used to try to open a file "-")
check report_stdout "robot.json data.csv" --robot robot.json --data data.csv --out - --report r5.html
written report_stdout "r5.calibration.json r5.html"
grep -q 'rcal-model/2' out_report_stdout && grep -q '<th>model file</th>' r5.html ||
    { echo "FAIL report_stdout: the model not on stdout or not on the page"; fail=1; }
# one drawing path: `rcal report` from the files the run wrote draws the page the run drew from memory (but
# for the report's own command line and date); the poses of the uncompensated figure are the data's, the
# tracker file's among them (600 cable rows and 60 position rows)
"$rcal" report --calibration r.calibration.json --model rmodel.json --out s.html 2> err_standalone ||
    { echo "FAIL standalone: rcal report failed"; cat err_standalone; fail=1; }
if diff <(grep -v '<th>this report</th>' r.html) <(grep -v '<th>this report</th>' s.html) > diff_standalone; then
    echo "ok   standalone: rcal report draws the page calibrate --report drew"
else
    echo "FAIL standalone: rcal report's page differs from calibrate --report's"; head -20 diff_standalone; fail=1
fi
if grep -q "over the data's 660 poses" r.html; then
    echo "ok   report: the uncompensated figure over the data's 660 poses (the tracker file's included)"
else
    echo "FAIL report: the uncompensated figure is not over the data's 660 poses:"
    grep 'flange, uncompensated' r.html; fail=1
fi
exit $fail
