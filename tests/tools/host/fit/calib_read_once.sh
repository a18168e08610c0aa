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
# shellcheck source=SCRIPTDIR/../../../common/read_once.sh
. "$src/tests/common/read_once.sh"
fail=0
read_once_fixture || exit 1
# check NAME FILES ARGS...: rcal calibrate ARGS under strace; each of FILES opened exactly once
check() { read_once_check calibrate "$@"; }
check all "robot.json data.csv val.csv pos.csv" --robot robot.json --data data.csv --validate val.csv \
    --positions pos.csv --out model.json --plots plots
check residuals "robot.json data.csv val.csv" --robot robot.json --data data.csv --validate val.csv \
    --residuals res.csv --out model2.json --json
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
