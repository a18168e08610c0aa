#!/bin/bash
# SPDX-License-Identifier: MIT
# golden_check.sh - every output of a fixed set of rcal runs against the
# recorded ones (issue 35: a refactoring changes no output byte).
#
# Runs a fixed list of `rcal` commands (and `rcal-rt --emit-c`) on the shipped
# data (data/, tests/tools/host/comp/data/every_form.mod, files made with `rcal simulate`
# at fixed seeds) in a temporary directory, each run in a directory of its own,
# and compares, run by run, its stdout, its stderr (when not empty), its exit
# status and every file it wrote with tests/system/golden/<run>/ (the same names;
# stdout, stderr, status; a written file under its own name, plots/... kept).
# Before the comparison every output goes through the masks below (the only
# figures that may change from one run to the next); after them the
# comparison is byte for byte. A file that differs only in numbers within
# 1e-9 relative or 1e-12 absolute (another CPU's libm: glibc picks FMA
# variants per CPU) is reported "not byte-identical, within 1e-9" (a warning,
# the check passes); any other difference fails the check with the run, the
# file and the first lines of a unified diff.
#
# Masks (mask() and mask_err(), in this order):
#   1. absolute paths: the temporary directory, the build directory and the
#      source directory -> <WORK>, <BUILD>, <SRC> (default paths in hints,
#      provenance);
#   2. timings: a number followed by ms, us, ns or s and a delimiter ("14.11
#      ms", "1.29 us/target", "0.3 s elapsed") -> "<T> ms" etc. (RAPID's
#      "WaitTime 5" is a setting and kept); JSON members named time_*ms/us/s,
#      time_ratio_*, time_*per_target or *_ms, *_us, *_ns, *_s, *_seconds ->
#      <T>; the time and "x LM" columns of rcal compare's table (its 4th
#      "a +- b" and the number after it, with the blanks around them: their
#      width follows the figures) -> " <T> +- <T> <T> ";
#   3. dates and times of day (ISO 8601 2025-01-31[T12:34:56[.123][Z|+01:00]]:
#      the model's provenance date, the report's "calibrated"/"date (UTC)")
#      -> <DATE>;
#   4. SHA-256 digests (64 hex digits: the report's provenance hashes files
#      that hold the masked figures; those files are compared themselves)
#      -> <SHA256>;
#   5. a direction the data do not see at all (relative singular value below
#      1e-12: a null space, whose basis any change of start point or CPU
#      turns) -> its value "<ZERO>" and its combination "<NULL DIRECTION>",
#      and the words under it (which known set lands under which of several
#      such directions is as arbitrary) are dropped; a printed zero's sign
#      ("-0.00000") -> " 0.00000" (the width kept);
#   6. stderr only: the progress lines a long step prints every 5 s
#      ("WHAT N of M, T elapsed, about T left"; their number depends on the
#      host's speed) are dropped. Estimates ("about 12.0 min") come from the
#      cost model, not the host, and are kept (their seconds masked by 2).
# Runs that need the real file ../shared/data/robotcali.csv (beside the
# repository) form a second group, skipped with a message when it is absent.
#
# Usage: scripts/golden_check.sh BUILD_DIR [--record]
#   --record   rewrite tests/system/golden/ from this build (after a change that
#              alters outputs on purpose; review the diff before committing).
#   GOLDEN_DIR=DIR  compare with (or record into) DIR instead of tests/system/golden.
#   RCAL_REAL_DATA=FILE  the real file (default ../shared/data/robotcali.csv).
#   KEEP=1     keep the temporary directory.
# Exit: 0 every run identical (or within 1e-9), 1 a difference, a missing or
# extra file or run, 77 BUILD_DIR/tools/rcal missing. 4-8 s in a Release build
# on two shared cores, about 30 s under ASan + UBSan (Debug).
set -u
src=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 1 ] || { echo "usage: $0 BUILD_DIR [--record]"; exit 2; }
build=$(cd "$1" 2>/dev/null && pwd) || { echo "golden_check: no build directory $1: skipped"; exit 77; }
record=0
[ "${2:-}" = --record ] && record=1
R="$build/tools/rcal"
RT="$build/firmware_host/rcal-rt"
[ -x "$R" ] || { echo "golden_check: $R not built: skipped"; exit 77; }
gold=${GOLDEN_DIR:-$src/tests/system/golden}
real_src=${RCAL_REAL_DATA:-$src/../shared/data/robotcali.csv}
work=$(mktemp -d /tmp/rcal_golden_XXXXXX)
cleanup() { if [ "${KEEP:-0}" = 1 ]; then echo "work directory kept: $work"; else rm -rf "$work"; fi; }
trap cleanup EXIT
out="$work/.out" # masked outputs, one directory per run
mkdir -p "$out" "$work/in"
T0=$(date +%s.%N)

# mask FILE: the masked text of FILE on stdout (the masks of the header, in its order)
mask() {
    sed -E \
        -e "s#$work#<WORK>#g" \
        -e "s#$build#<BUILD>#g" \
        -e "s#$src#<SRC>#g" \
        -e 's#WaitTime ([0-9])#WaitTime@\1#g' \
        -e 's#[0-9]+([.][0-9]+)?([eE][-+]?[0-9]+)? ?(ms|us|ns|s)([/ ,;:).]|$)#<T> \3\4#g' \
        -e 's#WaitTime@#WaitTime #g' \
        -e 's#("(time_[a-z_]*(ms|us|ns|s|ratio_[a-z]+|per_target)|[a-z_]*_(ms|us|ns|s|seconds))"): ?-?[0-9][0-9.eE+-]*#\1: <T>#g' \
        -e '/^  [A-Za-z][A-Za-z0-9-]* +[0-9]+[.][0-9]+ [+]- [0-9]/ {
                s# +[0-9]+[.][0-9]+ [+]- [0-9]+[.][0-9]+# <T> +- <T>#4
                s# <T> [+]- <T> +[0-9]+[.][0-9]+ +# <T> +- <T> <T> #
            }' \
        -e 's#[12][0-9]{3}-[01][0-9]-[0-3][0-9]([T ][0-2][0-9]:[0-5][0-9](:[0-5][0-9]([.][0-9]+)?)?(Z|[+-][0-2][0-9]:?[0-5][0-9])?)?#<DATE>#g' \
        -e 's#\b[0-9a-f]{64}\b#<SHA256>#g' \
        -e 's#NOT seen by the data \(relative singular value [0-9.]+e-(1[3-9]|[2-9][0-9])\): .*#NOT seen by the data (relative singular value <ZERO>): <NULL DIRECTION>#' \
        -e 's#( NOT seen by the data) \([0-9.]+e-(1[3-9]|[2-9][0-9])\):#\1 (<ZERO>):#' \
        -e 's#("sv_rel":[0-9.]+e-(1[3-9]|[2-9][0-9]),"identifiable":"no","combo":)"[^"]*"#\1"<NULL DIRECTION>"#g' \
        -e 's#-0[.](0+)\b# 0.\1#g' \
        "$1" | awk '
            # the words under a null direction: which of several directions at
            # round-off level (relative singular value below 1e-13) a known set
            # falls under is arbitrary, so the words are dropped there
            /<NULL DIRECTION>/ { print; nul = 1; next }
            nul && /^      [a-z]/ { next }
            { nul = 0; print }'
}
# mask_err FILE: mask, and drop the progress lines printed every 5 s of a long step (rch_progress_step:
# "WHAT N of M, T elapsed, about T left"; how many there are depends on the host's speed)
mask_err() {
    mask "$1" | grep -Ev ' [0-9]+ of [0-9]+, .* elapsed, about .* left$' || true
}

RUNS=()
# run NAME CMD...: CMD in $work/NAME (inputs as ../in/..., other runs' files as ../RUN/FILE);
# its masked stdout, stderr, status and written files into $out/NAME
run() {
    local name=$1 f
    shift
    RUNS+=("$name")
    mkdir -p "$work/$name" "$out/$name"
    (cd "$work/$name" && "$@" > "$work/$name.stdout" 2> "$work/$name.stderr")
    echo $? > "$out/$name/status"
    mask "$work/$name.stdout" > "$out/$name/stdout"
    mask_err "$work/$name.stderr" > "$out/$name/stderr"
    [ -s "$out/$name/stderr" ] || rm -f "$out/$name/stderr"
    (cd "$work/$name" && find . -type f | sed 's#^\./##') | while read -r f; do
        mkdir -p "$(dirname "$out/$name/$f")"
        mask "$work/$name/$f" > "$out/$name/$f"
    done
}

# ---- inputs ----
cp "$src"/data/* "$work/in/"
cp "$src/tests/tools/host/comp/data/every_form.mod" "$work/in/"
printf 'q1,q2,q3,q4,q5,q6\n10,20,30,40,50,50\n-30,10,5,0,60,-90\n45,-20,40,120,-45,180\n0,0,0,0,30,0\n' \
    > "$work/in/targets.csv"

# ---- group 1: the shipped data ----
D=../in/sim_irb120.csv
TR=../in/sim_irb120_truth.json
run cal_text "$R" calibrate --data "$D"
run cal_json "$R" calibrate --data "$D" --json --out model.json
run cal_truth "$R" calibrate --data "$D" --truth "$TR"
run cal_out "$R" calibrate --data "$D" --truth "$TR" --out model.json --residuals residuals.csv --plots plots \
    --report cal.html
run cal_cases3 "$R" calibrate --data "$D" --cases 3
run cal_holdout_groups "$R" calibrate --data "$D" --holdout-groups
run cal_effects_length_offset "$R" calibrate --data "$D" --effects length_offset
run cal_jumps "$R" calibrate --data "$D" --jumps --json
run cal_ltlm "$R" calibrate --data "$D" --method ltlm --no-prior
M=../cal_out/model.json

# tracker positions: the flange positions of the shipped truth (simulated with the truth's DH as the
# nominal robot: x, y, z are the FK of the nominal) seen by a tracker turned 90 deg about z and 1.5 m
# away (x' = 1500 - y, y' = x + 300, z' = z - 200)
awk '/"encoder_mm"/ { sub(/,[ \t]*$/, ""); print; print "}"; exit } { print }' "$work/in/sim_irb120_truth.json" \
    > "$work/in/truth_robot.json"
run sim_pos "$R" simulate --robot ../in/truth_robot.json --err-len-mm 0 --err-ang-deg 0 --q-step-deg 0.001 --out sim.csv --samples 80 --seed 7
awk -F, 'NR == 1 { print "q1,q2,q3,q4,q5,q6,x,y,z"; next }
    { printf "%s,%s,%s,%s,%s,%s,%.4f,%.4f,%.4f\n", $4, $5, $6, $7, $8, $9, 1500 - $2, $1 + 300, $3 - 200 }' \
    "$work/sim_pos/sim.csv" > "$work/in/positions.csv"
run cal_pos "$R" calibrate --positions ../in/positions.csv --out model.json
run cal_pos_cable "$R" calibrate --positions ../in/positions.csv --data "$D" --json
run eval_pos "$R" evaluate --model "$M" --positions ../in/positions.csv
run eval_pos_json "$R" evaluate --model ../cal_pos/model.json --positions ../in/positions.csv --json

# two encoder places: the shipped truth at its outlet and moved to (-250, -460, 10)
sed -E 's#"encoder_mm": *\[[^]]*\]#"encoder_mm": [-250, -460, 10]#' "$work/in/sim_irb120_truth.json" \
    > "$work/in/truth_outlet1.json"
run sim_outlet0 "$R" simulate --truth "$TR" --out sim.csv --samples 150 --seed 11 --q-step-deg 0.001
run sim_outlet1 "$R" simulate --truth ../in/truth_outlet1.json --out sim.csv --samples 150 --seed 12 --q-step-deg 0.001 --json
awk 'FNR == 1 { if (NR == 1) print $0 ",outlet"; next } { print $0 "," (NR == FNR ? 0 : 1) }' \
    "$work/sim_outlet0/sim.csv" "$work/sim_outlet1/sim.csv" > "$work/in/outlets.csv"
run cal_outlets "$R" calibrate --data ../in/outlets.csv --out model.json --residuals residuals.csv

# new data for evaluate: repeated poses (ISO 9283)
run sim_new "$R" simulate --seed 21 --samples 200 --repeats 5 --q-step-deg -1 --truth "$TR" --out new.csv
run eval_cable "$R" evaluate --model "$M" --data ../sim_new/new.csv --residuals residuals.csv
run eval_cable_json "$R" evaluate --model "$M" --data ../sim_new/new.csv --refit-encoder --json
run eval_outlets "$R" evaluate --model ../cal_outlets/model.json --data ../in/outlets.csv

run comp_csv "$R" compensate --model "$M" --in ../in/targets.csv --out compensated.csv --uncertainty-out u95.csv
run comp_csv_tool "$R" compensate --model "$M" --in ../in/targets.csv --out compensated.csv --tool 50,0,150 \
    --uncertainty-out u95.csv --json
run comp_rapid "$R" compensate --model "$M" --in ../in/every_form.mod --out every_form_cal.mod \
    --uncertainty-out u95.csv --summary

run export_urdf "$R" export --model "$M" --format urdf --out model.urdf
run export_dh_csv "$R" export --model "$M" --format dh-csv --out model_dh.csv --json
run export_robot "$R" export --model ../in/irb120.json --format dh-csv
rt=0
if [ -x "$RT" ]; then
    rt=1
    run rt_emit_c "$RT" --emit-c "$M"
else
    echo "golden_check: $RT not built: the rcal-rt runs (rt_*) skipped"
fi

run diag_text "$R" diagnose --data "$D" --plots plots
run diag_json "$R" diagnose --data "$D" --json --folds 3 --out model.json
run report "$R" report --calibration ../cal_json.stdout --model ../cal_json/model.json \
    --diagnosis ../diag_json.stdout --tolerance-mm 0.05 --out report.html

run poses "$R" poses --count 12 --seed 3 --out plan.csv
run poses_rapid "$R" poses --count 8 --seed 4 --outlet 250,-460,10 --outlet -250,-460,10 --split \
    --format rapid --out plan.mod --json
run fkcheck "$R" fkcheck --data "$D"
run fkcheck_json "$R" fkcheck --data ../sim_new/new.csv --json
run compare "$R" compare --data "$D" --cases 2
run compare_prior "$R" compare --data "$D" --cases 2 --methods LM,LTLM --prior --json
run kr6_sim "$R" simulate --robot ../in/kr6.json --out sim.csv --truth-out truth.json --samples 100 --seed 5
run kr6_cal "$R" calibrate --robot ../in/kr6.json --data ../kr6_sim/sim.csv

# ---- group 2: the real IRB120 file beside the repository ----
real=0
if [ -f "$real_src" ]; then
    real=1
    cp "$real_src" "$work/in/robotcali.csv"
    run real_cal "$R" calibrate --data ../in/robotcali.csv
    run real_cal_jumps_dq "$R" calibrate --data ../in/robotcali.csv --jumps --dequantize-joints --out model.json
    run real_fkcheck "$R" fkcheck --data ../in/robotcali.csv
    run real_diag "$R" diagnose --data ../in/robotcali.csv
    run real_comp_rapid "$R" compensate --model ../real_cal_jumps_dq/model.json --in ../in/every_form.mod \
        --out every_form_cal.mod --uncertainty-out u95.csv
else
    echo "golden_check: $real_src absent: the real-file runs (real_*) skipped"
fi

# ---- record ----
if [ $record = 1 ]; then
    mkdir -p "$gold"
    for d in "$gold"/*/; do
        [ -d "$d" ] || continue
        n=$(basename "$d")
        case $n in real_*) [ $real = 1 ] || continue ;; rt_*) [ $rt = 1 ] || continue ;; esac
        rm -rf "$d"
    done
    for n in "${RUNS[@]}"; do cp -R "$out/$n" "$gold/$n"; done
    printf 'golden_check: recorded %d runs into %s (%.1f s)\n' "${#RUNS[@]}" "$gold" \
        "$(echo "$(date +%s.%N) - $T0" | bc)"
    exit 0
fi

# ---- compare ----
# near EXPECTED ACTUAL: exit 0 when the files differ only in numbers within 1e-9 relative or 1e-12 absolute
near() {
    awk -v rel=1e-9 -v abstol=1e-12 '
    function numeq(x, y,   d, m) {
        if (x == y) return 1
        d = x - y; if (d < 0) d = -d
        m = x < 0 ? -x : x; if (y < 0 && -y > m) m = -y; if (y > m) m = y
        return d <= abstol || d <= rel * m
    }
    function lineeq(a, b,   re, sa, la) {
        re = "[-+]?([0-9]+[.]?[0-9]*|[.][0-9]+)([eE][-+]?[0-9]+)?"
        while (1) {
            if (!match(a, re)) return !match(b, re) && a == b
            sa = RSTART; la = RLENGTH
            if (!match(b, re)) return 0
            if (substr(a, 1, sa - 1) != substr(b, 1, RSTART - 1)) return 0
            if (!numeq(substr(a, sa, la) + 0, substr(b, RSTART, RLENGTH) + 0)) return 0
            a = substr(a, sa + la); b = substr(b, RSTART + RLENGTH)
        }
    }
    BEGIN {
        while ((getline a < ARGV[1]) > 0) {
            if ((getline b < ARGV[2]) <= 0) exit 1
            if (a != b && !lineeq(a, b)) exit 1
        }
        if ((getline b < ARGV[2]) > 0) exit 1
        exit 0
    }' "$1" "$2"
}
same=0 nearly=0 failed=0
fail_lines=()
for n in "${RUNS[@]}"; do
    bad=0 warn=0
    if [ ! -d "$gold/$n" ]; then
        echo "FAIL $n: no expected files ($gold/$n; record them with --record)"
        failed=$((failed + 1)); continue
    fi
    files=$( (cd "$out/$n" && find . -type f; cd "$gold/$n" && find . -type f) | sed 's#^\./##' | sort -u)
    for f in $files; do
        if [ ! -f "$gold/$n/$f" ]; then
            echo "FAIL $n: $f written but not expected"; bad=1; continue
        fi
        if [ ! -f "$out/$n/$f" ]; then
            echo "FAIL $n: $f expected but not written"; bad=1; continue
        fi
        cmp -s "$gold/$n/$f" "$out/$n/$f" && continue
        if near "$gold/$n/$f" "$out/$n/$f"; then
            echo "WARN $n: $f not byte-identical, within 1e-9"; warn=1
        else
            echo "FAIL $n: $f differs (expected $gold/$n/$f):"
            diff -u --label "expected/$n/$f" --label "actual/$n/$f" "$gold/$n/$f" "$out/$n/$f" | head -30
            bad=1
        fi
    done
    if [ $bad = 1 ]; then failed=$((failed + 1)); fail_lines+=("$n");
    elif [ $warn = 1 ]; then nearly=$((nearly + 1));
    else same=$((same + 1)); fi
done
# expected runs that were not run (a run dropped from the list without --record)
for d in "$gold"/*/; do
    [ -d "$d" ] || continue
    n=$(basename "$d")
    case $n in real_*) [ $real = 1 ] || continue ;; rt_*) [ $rt = 1 ] || continue ;; esac
    case " ${RUNS[*]} " in *" $n "*) ;; *) echo "FAIL $n: expected but not in the run list"; failed=$((failed + 1));; esac
done
total=${#RUNS[@]}
secs=$(echo "$(date +%s.%N) - $T0" | bc)
printf 'golden_check: identical: %d of %d runs' "$same" "$total"
[ $nearly -gt 0 ] && printf '; not byte-identical, within 1e-9: %d' "$nearly"
[ $failed -gt 0 ] && printf '; FAILED: %d (%s)' "$failed" "${fail_lines[*]:-}"
[ $real = 1 ] || printf '; real-file group skipped'
printf ' (%.1f s)\n' "$secs"
[ $failed -eq 0 ]
