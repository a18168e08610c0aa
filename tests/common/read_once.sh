# SPDX-License-Identifier: MIT
# read_once.sh - the strace harness of calib_read_once.sh and diag_read_once.sh (issue 50: no input opened
# twice, no output read back), sourced by both. The caller sets src (the repository), rcal (the program) and
# fail=0, and has cd'ed into its scratch directory.

# read_once_fixture: robot.json, data.csv, val.csv, touch.csv, part1.csv + part2.csv (data.csv in two files)
# and pos.csv (tracker positions of the simulated truth, as scripts/golden_check.sh makes them: the truth's
# flange seen by a tracker turned 90 deg about z). 0, or 1 when the simulation fails.
read_once_fixture() {
    cp "$src/data/sim_irb120.csv" data.csv
    cp "$src/data/sim_irb120.csv" val.csv
    cp "$src/data/irb120.json" robot.json
    cp "$src/fuzz/corpus/fuzz_touch/touches.csv" touch.csv
    head -301 "$src/data/sim_irb120.csv" > part1.csv
    { head -1 "$src/data/sim_irb120.csv"; tail -n +302 "$src/data/sim_irb120.csv"; } > part2.csv
    awk '/"encoder_mm"/ { sub(/,[ \t]*$/, ""); print; print "}"; exit } { print }' \
        "$src/data/sim_irb120_truth.json" > truth_robot.json
    "$rcal" simulate --robot truth_robot.json --err-len-mm 0 --err-ang-deg 0 --q-step-deg 0.001 --out sim.csv \
        --samples 60 --seed 7 > /dev/null || { echo "simulate failed"; return 1; }
    awk -F, 'NR == 1 { print "q1,q2,q3,q4,q5,q6,x,y,z"; next }
        { printf "%s,%s,%s,%s,%s,%s,%.4f,%.4f,%.4f\n", $4, $5, $6, $7, $8, $9, 1500 - $2, $1 + 300, $3 - 200 }' \
        sim.csv > pos.csv
}

# read_once_check CMD NAME FILES ARGS...: rcal CMD ARGS under strace (trace_NAME, out_NAME, err_NAME); the run
# must succeed (one cut short would open less) and each of FILES be opened exactly once
read_once_check() {
    local cmd=$1 name=$2 files=$3
    shift 3
    # LeakSanitizer cannot run under ptrace (an ASan build aborts at exit): leaks are the sanitizer ctest's
    # other tests' to find, this one counts opens
    ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" \
        strace -f -o "trace_$name" -e trace=openat "$rcal" "$cmd" "$@" > "out_$name" 2> "err_$name"
    local rc=$?
    if [ $rc -ne 0 ]; then
        echo "FAIL $name: rcal $cmd exited $rc"; cat "err_$name"; fail=1; return
    fi
    local f n
    for f in $files; do
        n=$(grep -v ENOENT "trace_$name" | grep -c "\"$f\"")
        if [ "$n" -ne 1 ]; then
            echo "FAIL $name: $f opened $n times (want 1)"; grep "\"$f\"" "trace_$name"; fail=1
        else
            echo "ok   $name: $f opened once"
        fi
    done
}

# written NAME FILES: each of FILES (outputs) never opened by its own name (read back), its temporary file
# opened once, to be created, and the file written
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
