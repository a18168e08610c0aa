#!/bin/sh
# SPDX-License-Identifier: MIT
# bench_ceres.sh - rcal against Ceres (automatic differentiation) on the same
# model, start point and data: whole processes, run alternately.
#   scripts/bench_ceres.sh [BUILD_DIR (build)] [RUNS (21)]
# Installs libceres-dev when missing (root, apt), builds bench/ceres outside
# the main build (in BUILD_DIR/ceres-bench), then for data/sim_irb120.csv and
# ../shared/data/robotcali.csv (when present) times `rcal calibrate
# --test-fraction 0` and ceres_fit alternately and prints medians, the ratio,
# both final RMS and where Ceres first reached rcal's final RMS (the stopping
# rules differ: Ceres runs to its function tolerance or 100 iterations),
# and last the floor of this way of timing (an empty process, rcal --version).
# Not part of the default build or the test run.
set -eu
cd "$(dirname "$0")/.."
BUILD=${1:-build}
RUNS=${2:-21}
RCAL=$BUILD/tools/rcal
[ -x "$RCAL" ] || { echo "bench_ceres: build rcal first ($RCAL missing)" >&2; exit 1; }
if ! dpkg -s libceres-dev >/dev/null 2>&1; then
    apt-get install -y libceres-dev >/dev/null
    # libceres-dev pulls in ATLAS, whose install points the system's BLAS and
    # LAPACK alternatives at it; rcal links the reference ones statically
    # (ATLAS's libblas.a does not link without its own libatlas): set them back
    ma=$(gcc -print-multiarch)
    for a in libblas.so libblas.so.3; do
        update-alternatives --set "$a-$ma" "/usr/lib/$ma/blas/$a" >/dev/null 2>&1 || true
    done
    for a in liblapack.so liblapack.so.3; do
        update-alternatives --set "$a-$ma" "/usr/lib/$ma/lapack/$a" >/dev/null 2>&1 || true
    done
fi
CB=$BUILD/ceres-bench
cmake -S bench/ceres -B "$CB" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$CB" >/dev/null
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
ALLDH=a1,d1,alpha1,theta1,a2,d2,alpha2,theta2,a3,d3,alpha3,theta3,a4,d4,alpha4,theta4,a5,d5,alpha5,theta5,a6,d6,alpha6,theta6

now_us() { echo $(($(date +%s%N) / 1000)); }
median() { sort -n | awk '{a[NR] = $1} END {printf "%.2f", a[int((NR + 1) / 2)] / 1000}'; }

for DATA in data/sim_irb120.csv ../shared/data/robotcali.csv; do
    [ -f "$DATA" ] || { echo "$DATA: absent, skipped"; continue; }
    # the start both fit from: nominal DH + rcal's encoder fit (DH held)
    "$RCAL" calibrate --data "$DATA" --test-fraction 0 --fix "$ALLDH" --out "$TMP/start.json" >/dev/null
    : > "$TMP/r"; : > "$TMP/c"
    i=0
    while [ $i -lt "$RUNS" ]; do
        t0=$(now_us); "$RCAL" calibrate --data "$DATA" --test-fraction 0 >/dev/null; t1=$(now_us)
        "$CB/ceres_fit" "$TMP/start.json" "$DATA" >/dev/null; t2=$(now_us)
        echo $((t1 - t0)) >> "$TMP/r"; echo $((t2 - t1)) >> "$TMP/c"
        i=$((i + 1))
    done
    mr=$(median < "$TMP/r"); mc=$(median < "$TMP/c")
    "$RCAL" calibrate --data "$DATA" --test-fraction 0 --json > "$TMP/r.json"
    r0=$(sed -n 's/.*"train_before": *{[^}]*"rmse_mm": *\([0-9.eE+-]*\).*/\1/p' "$TMP/r.json")
    r1=$(sed -n 's/.*"train_after": *{[^}]*"rmse_mm": *\([0-9.eE+-]*\).*/\1/p' "$TMP/r.json")
    it=$(sed -n 's/.*"iterations": *\([0-9]*\).*/\1/p' "$TMP/r.json")
    echo "$DATA: $RUNS runs each, whole process, alternating"
    echo "  rcal calibrate --test-fraction 0   median $mr ms   $it iterations, train RMS $r0 -> $r1 mm"
    echo "  ceres_fit (autodiff, LM, dense QR) median $mc ms   $("$CB/ceres_fit" "$TMP/start.json" "$DATA" --target-rms "$r1")"
    awk -v r="$mr" -v c="$mc" 'BEGIN {printf "  ratio ceres / rcal: %.1fx\n", c / r}'
done
# What this way of timing costs by itself: an empty process (/bin/true) and
# rcal doing nothing (--version), timed like the runs above. A ratio above
# ceres / floor cannot be measured here.
: > "$TMP/t"; : > "$TMP/v"
i=0
while [ $i -lt "$RUNS" ]; do
    t0=$(now_us); /bin/true; t1=$(now_us); "$RCAL" --version >/dev/null; t2=$(now_us)
    echo $((t1 - t0)) >> "$TMP/t"; echo $((t2 - t1)) >> "$TMP/v"
    i=$((i + 1))
done
echo "timing floor: empty process (/bin/true) median $(median < "$TMP/t") ms, rcal --version median $(median < "$TMP/v") ms"
