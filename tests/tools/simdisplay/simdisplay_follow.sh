#!/bin/sh
# SPDX-License-Identifier: MIT
# The follow check end to end at a second place of the encoder and on a
# second point of a tool plate, with rcal_simdisplay: a display frozen from
# the start (--freeze-after 1) is refused at outlet 1 and at plate point 1
# with nothing recorded (before: outlet 1 was recorded whole, unchecked);
# the display follows a plate plan (--cable-point) and both points are
# recorded; without the plate's points rcal acquire stops before recording
# and rcal_simdisplay at start, each naming --cable-point.
# usage: simdisplay_follow.sh RCAL SIMDISPLAY SOURCE_DIR WORK_DIR
set -u
R=$1 SD=$2 SRC=$3 W=$4
rm -rf "$W" && mkdir -p "$W" && cd "$W" || exit 1
SIM=
fail() { echo "FAIL: $*"; [ -n "$SIM" ] && kill "$SIM" 2>/dev/null; exit 1; }
TRUTH=$SRC/data/sim_irb120_truth.json
PTS="--cable-point 30,0,20 --cable-point -30,0,20"
# start the display with "$@"; wait for its pty
sim() {
  rm -f tty.sim
  "$SD" --protocol ascii --truth "$TRUTH" --follow ann.txt --rate-hz 100 --noise-mm 0.003 --link tty.sim \
    --max-seconds 120 "$@" >/dev/null 2>sim.err &
  SIM=$!
  n=0
  until [ -e tty.sim ]; do
    kill -0 $SIM 2>/dev/null || fail "the display stopped: $(cat sim.err)"
    n=$((n + 1)); [ $n -lt 100 ] || fail "no pty in 10 s"
    sleep 0.1
  done
}
unsim() { kill "$SIM"; wait "$SIM" 2>/dev/null; SIM=; }
acq() { "$R" acquire --port tty.sim --backend posix --protocol ascii --announce ann.txt --settle-ms 100 \
  --retries 2 --quiet "$@"; }
rows() { [ -f "$1" ] && tail -n +2 "$1" | wc -l || echo 0; }

# a frozen display at outlet 1 of a two-place plan
"$R" poses --count 4 --outlet 250,-460,10 --outlet -250,-460,10 --out plan.csv >/dev/null 2>&1 || fail "rcal poses --outlet"
sim --poses plan.csv --outlet 250,-460,10 --outlet -250,-460,10 --freeze-after 1
acq --poses plan.csv --outlet 1 --encoder -250,-460,10 --out frozen_o1.csv 2>err.txt && fail "frozen at outlet 1: exit 0"
unsim
grep -q REFUSED err.txt || fail "frozen at outlet 1: no refusal: $(cat err.txt)"
[ "$(rows frozen_o1.csv)" -eq 0 ] || fail "frozen at outlet 1: $(rows frozen_o1.csv) rows recorded"

# a tool plate: the display follows each point; a frozen one is refused on point 1
"$R" poses --count 4 --tool 50,0,150 $PTS --out plate.csv >poses.txt 2>&1 || fail "rcal poses --cable-point"
# the plan says how to record it: per point, with the points the follow check predicts from
grep -q -- "--target P $PTS" poses.txt || fail "rcal poses on a plate: its 'record them with' lacks --target and the points"
"$SD" --protocol ascii --truth "$TRUTH" --poses plate.csv --follow ann.txt --link tty.sim >/dev/null 2>sim.err \
  && fail "simdisplay on a plate plan without --cable-point: exit 0"
grep -q -- "--cable-point X,Y,Z" sim.err && grep -q "plate.csv:2:" sim.err || fail "simdisplay's message: $(cat sim.err)"
sim --poses plate.csv --cable-point 30.02,0,20 --cable-point -30,0.01,20
for p in 0 1; do
  acq --poses plate.csv --target $p $PTS --encoder 250,-460,10 --out plate_data.csv 2>err.txt \
    || fail "rcal acquire --target $p: $(cat err.txt)"
done
acq --poses plate.csv --target 1 --encoder 250,-460,10 --out nopoints.csv 2>err.txt && fail "no --cable-point: exit 0"
unsim
grep -q -- "--cable-point X,Y,Z" err.txt || fail "no --cable-point: message $(cat err.txt)"
[ ! -e nopoints.csv ] || fail "no --cable-point: a file was created"
[ "$(rows plate_data.csv)" -eq 8 ] || fail "plate: $(rows plate_data.csv) rows (want 8)"
sim --poses plate.csv $PTS --freeze-after 1
acq --poses plate.csv --target 1 $PTS --encoder 250,-460,10 --out frozen_p1.csv 2>err.txt && fail "frozen on point 1: exit 0"
unsim
grep -q REFUSED err.txt || fail "frozen on point 1: no refusal: $(cat err.txt)"
[ "$(rows frozen_p1.csv)" -eq 0 ] || fail "frozen on point 1: $(rows frozen_p1.csv) rows recorded"
echo "ok: frozen displays refused at outlet 1 and on plate point 1, nothing recorded; the plate followed (8 rows)"
