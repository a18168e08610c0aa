#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# scripts/valgrind_tests.sh - the ctest suite under valgrind memcheck (issue 7).
#
# Builds a non-sanitized RelWithDebInfo tree, asks ctest for every test's
# command, environment and working directory (ctest --show-only=json-v1), and
# runs each test executable under
#   valgrind --leak-check=full --errors-for-leak-kinds=definite,indirect,possible
# Child processes the tests start (rcal, rcal_simdisplay, ...) are traced too,
# except system programs (python3, the compiler; see --trace-children-skip). A test fails on its own failure or on
# any memcheck error or leak in it or its children. Disabled tests are skipped;
# tests labelled `study` (many whole runs of paths the others take; they run
# in the Release ctest only) are left out, as are
# tests whose command is not an executable of the build tree (scripts:
# python, cmake -E env, shell) are not run again here: memcheck cannot see
# into them, and the Release and sanitizer ctest runs already ran them.
#
# Environment:
#   BUILD_DIR          build tree (default <repo>/build-valgrind)
#   VALGRIND_EXCLUDE   extended regex of test names to skip. Default
#                      '^(diag_sim|drv_e2e)$': diag_sim is a long simulation
#                      (13+ min under memcheck, the same code paths as
#                      diag_stats/diag_cli), drv_e2e runs rcal against the
#                      simulated display on a pty with real timeouts that a
#                      30x slow-down breaks. Both run under ASan+UBSan+LSan in
#                      the RCAL_SANITIZE build. diag_sensors runs rcal 61 times
#                      on the independent generator's files (282 s under
#                      memcheck; diag_cli and sens_gen_check run the same
#                      diagnose code under it). pkg_limits_define_refused and
#                      pkg_limits_link_refused run the compiler and pass on
#                      the error it prints (ctest's PASS_REGULAR_EXPRESSION),
#                      which this script cannot judge; no project code runs.
#                      diag_indep (the independent generator's 100 diagnoses:
#                      509 s under memcheck, a third of the whole valgrind run;
#                      the same paths as diag_cli and host_prior) and
#                      robust_issue23 (it closes stdout with >&- and checks the
#                      exit status: memcheck's own descriptors change what a
#                      closed stdout is; its sanitizer run is the check) run
#                      under ASan+UBSan+LSan only. robust_hostile_cli (81 runs of
#                      rcal on hostile inputs: 644 s under memcheck) and
#                      methods_cli (55 runs: 253 s) and diag_chain (diagnose
#                      chains run to their end: 329 s) take the CLI paths the
#                      golden runs and the *_cli tests here take once; their
#                      many runs are the sanitizer build's (CI time).
#                      robust_inputs_cli (rcal on every malformed input
#                      file: 83 s under memcheck; the same parsers are fuzzed
#                      under ASan+UBSan and read under memcheck by the *_cli
#                      tests). ik_general and ik_branch (tens of thousands of IK
#                      solves near singularities, 10 s each in Release): the
#                      sanitizer build's; comp_urscript, comp_krl_conv run
#                      the IK under memcheck.
#                      Set it to '' to run everything.
#   VALGRIND_TIMEOUT   seconds per test (default 900)
#   VALGRIND_CHILDREN  1: trace child processes (default), 0: only the test
#   JOBS               tests run at the same time (default 1; scripts/test.sh
#                      passes the number of cores)
#   VALGRIND_FIRST     names of tests started first, the longest (about 4-9
#                      min each under memcheck), space separated
set -u -o pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD_DIR=${BUILD_DIR:-$ROOT/build-valgrind}
EXCLUDE=${VALGRIND_EXCLUDE-^(diag_sim|diag_indep|diag_sensors|drv_e2e|robust_issue23|robust_hostile_cli|robust_inputs_cli|methods_cli|diag_chain|pkg_limits_define_refused|pkg_limits_link_refused|ik_general|ik_branch)\$}
TMO=${VALGRIND_TIMEOUT:-900}
CHILDREN=${VALGRIND_CHILDREN:-1}
JOBS=${JOBS:-1}
FIRST=${VALGRIND_FIRST-methods_recover diag_cli methods_paper comp_cli}
start=$(date +%s)

command -v valgrind >/dev/null || { echo "valgrind: not installed (apt-get install valgrind)"; exit 1; }

echo "== valgrind: building $BUILD_DIR (no sanitizers)"
mkdir -p "$BUILD_DIR"
if ! cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRCAL_SANITIZE=OFF -DRCAL_STATIC_PROGRAM=OFF \
    >"$BUILD_DIR/valgrind-cfg.log" 2>&1; then
    cat "$BUILD_DIR/valgrind-cfg.log"
    echo "valgrind: configure FAILED"
    exit 1
fi
if ! cmake --build "$BUILD_DIR" -j"$(nproc 2>/dev/null || echo 2)" >"$BUILD_DIR/valgrind-build.log" 2>&1; then
    tail -40 "$BUILD_DIR/valgrind-build.log"
    echo "valgrind: build FAILED"
    exit 1
fi

LOGDIR="$BUILD_DIR/valgrind"
rm -rf "$LOGDIR"
mkdir -p "$LOGDIR"

# One line per test, fields separated by \x1e (not a tab: read would merge
# empty fields): name, workdir, env (\x1f-joined), disabled, argv (\x1f-joined)
(cd "$BUILD_DIR" && ctest --show-only=json-v1) | python3 -c '
import json, sys
for t in json.load(sys.stdin)["tests"]:
    props = {p["name"]: p["value"] for p in t.get("properties", [])}
    env = props.get("ENVIRONMENT", [])
    if "study" in props.get("LABELS", []):
        continue  # the studies: the Release run only (label study; scripts/test.sh)
    print("\x1e".join([t["name"], props.get("WORKING_DIRECTORY", "."), "\x1f".join(env),
                     "1" if props.get("DISABLED") else "0", "\x1f".join(t.get("command", []))]))
' >"$LOGDIR/tests.tsv" || { echo "valgrind: ctest --show-only failed"; exit 1; }

# No --error-exitcode: a child's memcheck status would be mistaken for its own
# (and /bin/sh's for the test's); findings are read from the logs instead, of
# programs of the build tree only (the shell of system() is traced so that
# the rcal it starts is, but its own findings are not ours).
VG=(valgrind --tool=memcheck --leak-check=full --show-leak-kinds=definite,indirect,possible
    --errors-for-leak-kinds=definite,indirect,possible --num-callers=30 --track-fds=no)
if [ "$CHILDREN" = 1 ]; then
    # System programs the tests start are not traced: python3 (a test's JSON
    # check: 30-40 s each under memcheck, with pyenv's shell shims before it)
    # and the C compiler (a consumer of the public header built by a test).
    # Their children are none of ours. /bin/sh and timeout stay traced: the
    # rcal they start is.
    VG+=(--trace-children=yes
         "--trace-children-skip=*python3*,*/pyenv*,*/.pyenv/*,*/cc,*/gcc,*/gcc-[0-9]*,*/cc1,*/as,*/ld,*/collect2")
fi

run_test() { # name workdir env disabled argv
    local name=$1 wd=$2 envs=$3 argv=$4 rc t0 t1 status log
    local -a cmd envv=()
    IFS=$'\x1f' read -r -a cmd <<<"$argv"
    IFS=$'\x1f' read -r -a envv <<<"$envs"
    log="$LOGDIR/$name"
    t0=$(date +%s)
    if [[ ${cmd[0]:-} == "$BUILD_DIR"/* ]] && [ "$(head -c 4 "${cmd[0]}" 2>/dev/null | tr -d '\177')" = ELF ]; then
        (cd "$wd" && env "${envv[@]}" timeout "$TMO" "${VG[@]}" --log-file="$log.%p.vg" "${cmd[@]}") \
            >"$log.out" 2>&1
        rc=$?
    else
        # A script (python, cmake -E env, sh): memcheck would not see into it,
        # and the Release and sanitizer ctest runs already run it as it is.
        printf '%-24s %-8s %5s   %s\n' "$name" "-" "-" "skipped (not a program of the build tree; run by ctest)" \
            >"$log.result"
        return 0
    fi
    t1=$(date +%s)
    # memcheck findings in the test or any traced child
    local errs=0 leaks="" f exe
    for f in "$log".*.vg; do
        [ -e "$f" ] || continue
        exe=$(sed -n 's/^==[0-9]*== Command: \([^ ]*\).*/\1/p' "$f" | head -1)
        if [[ $exe != "$BUILD_DIR"/* ]]; then
            rm -f "$f" # a system program (sh, ...): not ours
            continue
        fi
        if grep -q 'ERROR SUMMARY: [1-9]' "$f"; then errs=$((errs + 1)); fi
        leaks+=$(grep -hE '(definitely|indirectly|possibly) lost: [1-9]' "$f" | head -3)
    done
    local nlogs
    nlogs=$(ls "$log".*.vg 2>/dev/null | wc -l)
    if [ "$rc" = 124 ]; then
        status="FAIL (timeout ${TMO}s)"
    elif [ "$errs" -ne 0 ]; then
        status="FAIL (memcheck errors, see $log.*.vg)"
    elif [ "$rc" -ne 0 ]; then
        status="FAIL (test exit $rc, see $log.out)"
    else
        status=ok
    fi
    printf '%-24s %-8s %5ss  %s\n' "$name" "vg x$nlogs" "$((t1 - t0))" "$status" >"$log.result"
    [ -n "$leaks" ] && echo "$leaks" | sed 's/^/    /' >>"$log.result"
}

# The longest tests first (the makespan with JOBS at a time is then about
# the sum over JOBS, not a long test left alone at the end); then ctest's order.
awk -F'\x1e' -v first="$FIRST" 'BEGIN { n = split(first, f, " "); for (i = 1; i <= n; i++) rank[f[i]] = i }
  { print ($1 in rank ? rank[$1] : 1000) "\x1e" NR "\x1e" $0 }' "$LOGDIR/tests.tsv" |
    sort -t$'\x1e' -k1,1n -k2,2n | cut -d$'\x1e' -f3- >"$LOGDIR/order.tsv"
echo "== valgrind: running $(grep -c . "$LOGDIR/tests.tsv") tests, $JOBS at a time"
running=0
while IFS=$'\x1e' read -r name wd envs disabled argv; do
    if [ "$disabled" = 1 ]; then
        printf '%-24s %-8s %5s   %s\n' "$name" "-" "-" "skipped (disabled)" >"$LOGDIR/$name.result"
        continue
    fi
    if [ -n "$EXCLUDE" ] && [[ $name =~ $EXCLUDE ]]; then
        printf '%-24s %-8s %5s   %s\n' "$name" "-" "-" "skipped (VALGRIND_EXCLUDE)" >"$LOGDIR/$name.result"
        continue
    fi
    run_test "$name" "$wd" "$envs" "$argv" </dev/null &
    running=$((running + 1))
    if [ "$running" -ge "$JOBS" ]; then
        wait -n
        running=$((running - 1))
    fi
done <"$LOGDIR/order.tsv"
wait

pass=0
failn=0
printf '%-24s %-8s %6s  %s\n' test "run (processes)" time result
while IFS=$'\x1e' read -r name _; do
    if [ ! -f "$LOGDIR/$name.result" ]; then
        printf '%-24s %-8s %5s   %s\n' "$name" "-" "-" "FAIL (no result: the runner broke)" >"$LOGDIR/$name.result"
    fi
    cat "$LOGDIR/$name.result"
    if grep -q ' ok$' "$LOGDIR/$name.result"; then
        pass=$((pass + 1))
    elif grep -q 'FAIL' "$LOGDIR/$name.result"; then
        failn=$((failn + 1))
    fi
done <"$LOGDIR/tests.tsv"
for f in "$LOGDIR"/*.result; do
    if grep -q 'memcheck errors' "$f"; then
        n=$(basename "$f" .result)
        for v in "$LOGDIR/$n".*.vg; do
            grep -q 'ERROR SUMMARY: [1-9]' "$v" && { echo "---- $v"; grep -v '^==[0-9]*== *$' "$v" | head -60; }
        done
    fi
done
echo "== valgrind: $(($(date +%s) - start)) s"
echo "valgrind: $pass passed, $failn failed"
[ "$failn" -eq 0 ]
