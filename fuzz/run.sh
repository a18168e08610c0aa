#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# fuzz/run.sh - build the libFuzzer targets (clang, ASan + UBSan) and run each
# for a bounded time. Fails when any target crashes, leaks, times out on one
# input or breaks one of its invariants; prints executions per target.
#
# Environment:
#   FUZZ_SECONDS   seconds per target (default 45)
#   FUZZ_JOBS      targets run at the same time (default 1; 2 on an idle
#                  2-core CI machine halves the wall time)
#   FUZZ_TARGETS   space-separated subset (default: every target built)
#   BUILD_DIR      build directory (default: <repo>/build-fuzz)
#   CC             compiler (default clang; must be clang)
#
# Seeds come from fuzz/corpus/<target>/ (read only); new inputs found go to
# $BUILD_DIR/corpus/<target>/, crash inputs to $BUILD_DIR/artifacts/. To
# replay one: $BUILD_DIR/<target> <file>.
set -u -o pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
FUZZ_SECONDS=${FUZZ_SECONDS:-45}
FUZZ_JOBS=${FUZZ_JOBS:-1}
BUILD_DIR=${BUILD_DIR:-$ROOT/build-fuzz}
CC=${CC:-clang}
case "$CC" in *clang*) ;; *) CC=clang ;; esac

echo "== fuzz: building with $CC in $BUILD_DIR"
if ! CC=$CC cmake -S "$ROOT/fuzz" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo >"$BUILD_DIR.cfg.log" 2>&1; then
    cat "$BUILD_DIR.cfg.log"
    echo "fuzz: configure failed"
    exit 1
fi
rm -f "$BUILD_DIR.cfg.log"
if ! cmake --build "$BUILD_DIR" -j"$(nproc 2>/dev/null || echo 2)" >"$BUILD_DIR/build.log" 2>&1; then
    cat "$BUILD_DIR/build.log"
    echo "fuzz: build failed"
    exit 1
fi

if [ -n "${FUZZ_TARGETS:-}" ]; then
    targets=$FUZZ_TARGETS
else
    targets=$(cat "$BUILD_DIR/fuzz_targets.txt")
fi

dict_for() {
    case "$1" in
    fuzz_csv | fuzz_plan | fuzz_targets | fuzz_positions | fuzz_pos_load | fuzz_touch) echo "$ROOT/fuzz/dict/csv.dict" ;;
    fuzz_json | fuzz_robot) echo "$ROOT/fuzz/dict/json.dict" ;;
    fuzz_rapid) echo "$ROOT/fuzz/dict/rapid.dict" ;;
    fuzz_fanuc) echo "$ROOT/fuzz/dict/fanuc.dict" ;;
    fuzz_urscript) echo "$ROOT/fuzz/dict/urscript.dict" ;;
    fuzz_krl) echo "$ROOT/fuzz/dict/krl.dict" ;;
    fuzz_ascii | fuzz_stx | fuzz_display) echo "$ROOT/fuzz/dict/ascii.dict" ;;
    fuzz_urdf | fuzz_rsi) echo "$ROOT/fuzz/dict/xml.dict" ;;
    *) echo "" ;;
    esac
}

maxlen_for() {
    case "$1" in
    fuzz_csv | fuzz_plan | fuzz_targets | fuzz_positions | fuzz_pos_load | fuzz_touch | fuzz_json | fuzz_robot | fuzz_urdf | fuzz_rapid | fuzz_fanuc | fuzz_krl) echo 16384 ;;
    fuzz_egm) echo 2048 ;;
    *) echo 1024 ;;
    esac
}

mkdir -p "$BUILD_DIR/artifacts" "$BUILD_DIR/logs"

run_one() {
    local t=$1 work="$BUILD_DIR/corpus/$1" seeds="$ROOT/fuzz/corpus/$1" dict log
    log="$BUILD_DIR/logs/$t.log"
    mkdir -p "$work"
    dict=$(dict_for "$t")
    local args=(-max_total_time="$FUZZ_SECONDS" -timeout=10 -rss_limit_mb=2048
        -max_len="$(maxlen_for "$t")" -print_final_stats=1
        -artifact_prefix="$BUILD_DIR/artifacts/$t-")
    [ -n "$dict" ] && args+=(-dict="$dict")
    # first directory: where new inputs go; the checked-in seeds stay read only
    [ -d "$seeds" ] || seeds=
    "$BUILD_DIR/$t" "${args[@]}" "$work" ${seeds:+"$seeds"} >"$log" 2>&1
    echo $? >"$BUILD_DIR/logs/$t.rc"
}

start=$(date +%s)
echo "== fuzz: $(echo $targets | wc -w) targets x ${FUZZ_SECONDS}s, $FUZZ_JOBS at a time"
running=0
for t in $targets; do
    if [ ! -x "$BUILD_DIR/$t" ]; then
        echo "fuzz: no target $t"
        echo 127 >"$BUILD_DIR/logs/$t.rc"
        continue
    fi
    run_one "$t" &
    running=$((running + 1))
    if [ "$running" -ge "$FUZZ_JOBS" ]; then
        wait -n
        running=$((running - 1))
    fi
done
wait

fail=0
printf '%-18s %12s %8s %7s  %s\n' target executions exec/s corpus result
for t in $targets; do
    log="$BUILD_DIR/logs/$t.log"
    rc=$(cat "$BUILD_DIR/logs/$t.rc" 2>/dev/null || echo 127)
    execs=$(sed -n 's/^stat::number_of_executed_units: *\([0-9]*\).*/\1/p' "$log" 2>/dev/null | tail -1)
    [ -n "$execs" ] || execs=$(sed -n 's/^Done \([0-9]*\) runs.*/\1/p' "$log" 2>/dev/null | tail -1)
    [ -n "$execs" ] || execs=$(grep -o '#[0-9]*' "$log" 2>/dev/null | tail -1 | tr -d '#')
    rate=$(sed -n 's/^stat::average_exec_per_sec: *\([0-9]*\).*/\1/p' "$log" 2>/dev/null | tail -1)
    units=$(ls "$BUILD_DIR/corpus/$t" 2>/dev/null | wc -l)
    if [ "$rc" = 0 ]; then
        res=ok
    else
        res="FAIL (exit $rc)"
        fail=1
    fi
    printf '%-18s %12s %8s %7s  %s\n' "$t" "${execs:-?}" "${rate:-?}" "$units" "$res"
done
for t in $targets; do
    rc=$(cat "$BUILD_DIR/logs/$t.rc" 2>/dev/null || echo 127)
    if [ "$rc" != 0 ]; then
        echo "---- $t (exit $rc): end of $BUILD_DIR/logs/$t.log"
        grep -v '^#' "$BUILD_DIR/logs/$t.log" | tail -40
        ls "$BUILD_DIR/artifacts/$t-"* 2>/dev/null
    fi
done
echo "== fuzz: $(($(date +%s) - start)) s"
if [ "$fail" != 0 ]; then
    echo "fuzz: FAILED (replay an artifact with $BUILD_DIR/<target> <file>)"
    exit 1
fi
echo "fuzz: all targets passed"
