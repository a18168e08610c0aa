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
# shellcheck source=SCRIPTDIR/../../../common/read_once.sh
. "$src/tests/common/read_once.sh"
fail=0
read_once_fixture || exit 1
# check NAME FILES ARGS...: rcal diagnose ARGS under strace; each of FILES opened exactly once
check() { read_once_check diagnose "$@"; }
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
