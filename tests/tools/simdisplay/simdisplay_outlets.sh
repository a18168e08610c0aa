#!/bin/sh
# SPDX-License-Identifier: MIT
# The simulated display on a two-outlet plan (issue 33, item 8): without
# --outlet it stops at once with a message naming the option (and the
# README's wait loop, which also watches the process, ends); with the
# places it serves both runs of rcal acquire (--outlet 0, then 1) and the
# file holds every pose from its outlet.
# usage: simdisplay_outlets.sh RCAL SIMDISPLAY SOURCE_DIR WORK_DIR
set -u
R=$1 SD=$2 SRC=$3 W=$4
rm -rf "$W" && mkdir -p "$W" && cd "$W" || exit 1
fail() { echo "FAIL: $*"; [ -n "${SIM:-}" ] && kill "$SIM" 2>/dev/null; exit 1; }
"$R" poses --count 4 --outlet 250,-460,10 --outlet -250,-460,10 --out plan.csv >/dev/null 2>&1 || fail "rcal poses"
TRUTH=$SRC/data/sim_irb120_truth.json

# no place for outlet 1: refused at start, the message names --outlet
"$SD" --protocol ascii --truth "$TRUTH" --poses plan.csv --follow ann.txt --link tty.sim >/dev/null 2>err.txt &
SIM=$!
n=0
until [ -e tty.sim ]; do   # the README's wait loop
  kill -0 $SIM 2>/dev/null || { echo "the simulated display stopped: $(cat err.txt)"; break; }
  n=$((n + 1)); [ $n -lt 100 ] || fail "the wait loop did not end in 10 s"
  sleep 0.1
done
wait $SIM; rc=$?
SIM=
[ $rc -ne 0 ] || fail "exit 0 without the places"
grep -q -- "--outlet X,Y,Z" err.txt || fail "message does not name --outlet: $(cat err.txt)"
grep -q "plan.csv:[0-9]*: a pose from outlet 1" err.txt || fail "message has no file:line: $(cat err.txt)"
[ ! -e tty.sim ] || fail "a link left behind"

# with the places: both runs recorded
"$SD" --protocol ascii --truth "$TRUTH" --poses plan.csv --outlet 249.276,-460.393,9.827 --outlet -250,-460,10 \
  --follow ann.txt --noise-mm 0.005 --link tty.sim --max-seconds 120 >/dev/null 2>err.txt &
SIM=$!
n=0
until [ -e tty.sim ]; do
  kill -0 $SIM 2>/dev/null || fail "the display stopped: $(cat err.txt)"
  n=$((n + 1)); [ $n -lt 100 ] || fail "no pty in 10 s"
  sleep 0.1
done
# each run's --encoder is its place (the follow check predicts from it; issue: outlet 1 was not checked)
for k in 0 1; do
  enc=250,-460,10; [ $k -eq 1 ] && enc=-250,-460,10
  "$R" acquire --port tty.sim --backend posix --protocol ascii --poses plan.csv --outlet $k --encoder $enc \
    --out data.csv --announce ann.txt --settle-ms 100 --quiet || fail "rcal acquire --outlet $k"
done
kill $SIM; wait $SIM 2>/dev/null
rows=$(tail -n +2 data.csv | wc -l)
o1=$(tail -n +2 data.csv | awk -F, '$NF == 1' | wc -l)
[ "$rows" -eq 8 ] && [ "$o1" -eq 4 ] || fail "data.csv: $rows rows, $o1 from outlet 1 (want 8, 4)"
echo "ok: two-outlet plan served; without places refused with: $(cat "$W"/err.txt 2>/dev/null | head -1)"
