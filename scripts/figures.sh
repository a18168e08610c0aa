#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Regenerates every figure quoted in README.md, in one run, into out/figures/
# (text) and docs/figures/ (SVG). Needs a Release build in build/ (scripts/demo.sh)
# and ../shared/data/robotcali.csv for the real-data figures. Takes a few minutes.
# Every plot is written with its data as CSV beside it (same base name).
# PLOTS_ONLY=1 remakes only the plot directories under docs/ (about a minute:
# no benchmarks, no real-time loops), then lists any SVG without its CSV.
set -euo pipefail
cd "$(dirname "$0")/.."
R=build/tools/rcal
REAL=../shared/data/robotcali.csv
O=out/figures
F=docs/figures
mkdir -p "$O" "$F"
run() { local name=$1; shift; echo "== $name: $*"; "$@" > "$O/$name.txt" 2>&1 || echo "   (exit $?)"; }

# every plot quoted in README.md, into docs/ (SVG + CSV)
plots() {
  if [ -f "$REAL" ]; then
    run compare300 $R compare --data $REAL --cases 10 --samples 300 --test-fraction 0.1 --seed 1 --plots $F/compare300
    run compare200 $R compare --data $REAL --cases 10 --samples 200 --test-fraction 0.2 --seed 1 --plots $F/compare200
    run diagnose $R diagnose --data $REAL --plots docs/diagnose
    cp $O/diagnose.txt docs/diagnose/real_data_output.txt
    run uncertainty_real $R calibrate --data $REAL --plots $F/uncertainty_real
    run uncertainty_real_jumps $R calibrate --data $REAL --jumps --dequantize-joints --plots $F/uncertainty_real_jumps
    $R calibrate --data $REAL --jumps --dequantize-joints --out $O/real.json > /dev/null
    run grind_real_sim $R simulate --truth $O/real.json --out $O/sim_real.csv --samples 1000 --seed 5
    $R calibrate --data $O/sim_real.csv --out $O/cal_real.json > /dev/null
    run grind_real $R grind --model $O/cal_real.json --truth $O/real.json --plots $F/grind_real
  fi
  run chaos $R chaos --plots $F/chaos
  run grindA_sim $R simulate --out $O/simA.csv --truth-out $O/truthA.json --samples 1000 --seed 3
  $R calibrate --data $O/simA.csv --out $O/calA.json > /dev/null
  run grindA $R grind --model $O/calA.json --truth $O/truthA.json --plots $F/grindA
  for s in $(find $F docs/diagnose -name '*.svg'); do [ -f "${s%.svg}.csv" ] || echo "   no data beside $s"; done
}
if [ "${PLOTS_ONLY:-0}" = 1 ]; then plots; echo "plots in $F and docs/diagnose"; exit 0; fi

# issue 2: simulated truth, real data, FK, speed
run sim_simulate   $R simulate --seed 7 --samples 600 --q-step-deg -1 --out $O/simr.csv --truth-out $O/simr_truth.json
run sim_calibrate  $R calibrate --data $O/simr.csv --truth $O/simr_truth.json
run demo_calibrate $R calibrate --data data/sim_irb120.csv --truth data/sim_irb120_truth.json
run simq_simulate  $R simulate --seed 7 --samples 600 --group-size 20 --out $O/simq.csv --truth-out $O/simq_truth.json
run simq_calibrate $R calibrate --data $O/simq.csv --truth $O/simq_truth.json
if [ -f "$REAL" ]; then
  run fkcheck $R fkcheck --data $REAL
  for m in lm ltlm lm-paper ltlm-paper; do run real_$m $R calibrate --data $REAL --method $m --json; done
  run real_lm_report   $R calibrate --data $REAL
  run real_tool_offset $R calibrate --data $REAL --tool-offset
  run bench_real $R bench --runs 21
fi
# issue 3 (compare), 5 (grinding, real and simulated truth), 6 (diagnose), chaos study, uncertainty: the plots
plots
[ -f "$REAL" ] && run grind_real_pos $R grind --model $O/cal_real.json --truth $O/real.json --position-only
run bench_sim $R bench --data data/sim_irb120.csv --runs 21
# issue 5: compensation speed, real-time loop, cross-build
# the same with the joints recorded at 0.001 deg (a controller readout) instead of 0.1 deg
run grindA3_sim $R simulate --out $O/simA3.csv --truth-out $O/truthA3.json --samples 1000 --seed 3 --q-step-deg 0.001
$R calibrate --data $O/simA3.csv --out $O/calA3.json > /dev/null
run grindA3 $R grind --model $O/calA3.json --truth $O/truthA3.json
run rt_bench build/firmware_host/rcal-rt --bench --targets 200000 --repeat 5 --fifo
for hz in 250 500 1000; do run rt_loop_$hz build/firmware_host/rcal-rt --rate-hz $hz --seconds 20 --fifo; done
command -v arm-none-eabi-gcc >/dev/null && run cross_build sh firmware_host/cross_build.sh build/arm
# issue 4: poses and serial speed
run poses $R poses --count 30 --seed 1 --out $O/poses30.csv
run serial_bench build/tools/simdisplay/rcal_serial_bench
# issue 3: every method on a simulated robot; issue 4: end-to-end acquisition
run methods_recover build/tests/tools/host/fit/methods_recover
run drv_e2e ctest --test-dir build -R drv_e2e -V
# issue 6: detection rates of hidden effects (20 seeds each)
for spec in "0.01 1" "0.1 1" "0.1 3"; do
  set -- $spec
  build/tests/tools/host/studies/diag_rates 20 300 3 $1 $2 > docs/diagnose/rates_q$1_x$2.txt 2>&1 || echo "   (diag_rates exit $?)"
done
# issue 7: stack use of the core's public functions
run stack env TOP=10 bash scripts/stack_usage.sh
echo "figures in $O and $F"
