#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# scripts/static_analysis.sh - static analysis of rcal (issue 7). Zero
# findings or it fails.
#
#  1. the core (lib/*.c) compiled with gcc and clang under
#     -std=c99 -Wall -Wextra -Werror -pedantic -Wconversion -Wdouble-promotion
#     -Wshadow -Wsign-conversion -Wundef -Wmissing-prototypes (syntax only)
#  2. cppcheck --enable=warning,performance,portability over lib/, tools/,
#     drivers/, firmware_host/
#  3. clang-tidy (checks in .clang-tidy) over the same directories, with the
#     compile commands of a CMake build configured with clang
#
# Suppressions: inline in the code with their reason, or in
# scripts/static_suppressions.txt (file + check, each with its reason).
# A suppression that no longer matches anything is reported as stale.
#
# Environment: BUILD_DIR (default <repo>/build-static), JOBS (default nproc),
# STATIC_STEPS (default "warnings cppcheck tidy").
set -u -o pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD_DIR=${BUILD_DIR:-$ROOT/build-static}
JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}
STEPS=${STATIC_STEPS:-warnings cppcheck tidy}
SUPP="$ROOT/scripts/static_suppressions.txt"
DIRS=(lib tools drivers firmware_host)
cd "$ROOT" || exit 1
# rc_version.h (version and compile-time limits) for the steps that read lib/
cmake -DRCAL_HEADER_DIR="$BUILD_DIR/include" -P cmake/rcal_version_header.cmake || exit 1
fail=0
start=$(date +%s)

existing_dirs() {
    for d in "${DIRS[@]}"; do [ -d "$d" ] && echo "$d"; done
}

# suppressions of one tool: "check path" per line
supp_of() {
    sed -e 's/#.*//' "$SUPP" | awk -v t="$1" '$1 == t && NF >= 3 { print $2, $3 }'
}

# ---- 1. the core under the strict warning set ---------------------------------
if [[ " $STEPS " == *" warnings "* ]]; then
    echo "== static: core warnings (-Wconversion -Wdouble-promotion -Wshadow ...)"
    WFLAGS=(-std=c99 -Wall -Wextra -Werror -pedantic -Wconversion -Wdouble-promotion -Wshadow
        -Wsign-conversion -Wundef -Wmissing-prototypes -Wstrict-prototypes -Wcast-align
        -Wpointer-arith -Wwrite-strings -fsyntax-only -I lib -I "$BUILD_DIR/include")
    nw=0
    for cc in gcc clang; do
        if ! command -v $cc >/dev/null; then
            echo "static: $cc not found, skipped"
            continue
        fi
        for f in lib/*.c; do
            if ! out=$($cc "${WFLAGS[@]}" "$f" 2>&1); then
                echo "$out"
                nw=$((nw + 1))
            fi
        done
    done
    if [ "$nw" -ne 0 ]; then
        echo "static: core warnings: $nw file(s) FAILED"
        fail=1
    else
        echo "static: core warnings: $(ls lib/*.c | wc -l) files clean with gcc and clang"
    fi
fi

# ---- 2. cppcheck ----------------------------------------------------------------
if [[ " $STEPS " == *" cppcheck "* ]]; then
    echo "== static: $(cppcheck --version)"
    cpp_supp=$(mktemp)
    supp_of cppcheck | while read -r id path; do echo "$id:$ROOT/$path"; echo "$id:$path"; done >"$cpp_supp"
    mapfile -t src_dirs < <(existing_dirs)
    inc=(-I "$BUILD_DIR/include")
    while IFS= read -r d; do inc+=(-I "$d"); done < <(find "${src_dirs[@]}" -name '*.h' -printf '%h\n' | sort -u)
    cpp_out=$(mktemp)
    # RC_MAX_PARAMS as the build sets it; one configuration per file (the
    # #ifdef'ed alternatives are compile-time limits, not code paths).
    cppcheck --enable=warning,performance,portability --error-exitcode=1 --inline-suppr -q \
        --std=c99 --language=c -j "$JOBS" -DRC_MAX_PARAMS=96 -D_POSIX_C_SOURCE=200809L \
        --suppress=missingIncludeSystem --suppressions-list="$cpp_supp" \
        --template='{file}:{line}:{column}: {severity}: {message} [{id}]' \
        "${inc[@]}" "${src_dirs[@]}" >"$cpp_out" 2>&1
    rc=$?
    if [ "$rc" -ne 0 ] || grep -q ': \(error\|warning\|performance\|portability\|style\):' "$cpp_out"; then
        cat "$cpp_out"
        echo "static: cppcheck FAILED"
        fail=1
    else
        echo "static: cppcheck: 0 findings ($(supp_of cppcheck | wc -l) suppressed by file, see $(basename "$SUPP"))"
    fi
    # stale cppcheck suppressions: run again without them
    cppcheck --enable=warning,performance,portability --inline-suppr -q --std=c99 --language=c -j "$JOBS" \
        -DRC_MAX_PARAMS=96 -D_POSIX_C_SOURCE=200809L --suppress=missingIncludeSystem \
        --template='{file} [{id}]' "${inc[@]}" "${src_dirs[@]}" >"$cpp_out.all" 2>&1
    all_hits=$(sed -n 's/^\([^ ]*\) \[\(.*\)\]$/\2 \1/p' "$cpp_out.all" | sort -u) # "id file"
    supp_of cppcheck | while read -r id path; do
        hit=0
        while read -r hid hfile; do
            # shellcheck disable=SC2053
            [[ $hid == "$id" && $hfile == $path ]] && hit=1
        done <<<"$all_hits"
        [ "$hit" = 1 ] || echo "static: note: stale cppcheck suppression: $id $path"
    done
    rm -f "$cpp_supp" "$cpp_out" "$cpp_out.all"
fi

# ---- 3. clang-tidy ----------------------------------------------------------------
if [[ " $STEPS " == *" tidy "* ]]; then
    echo "== static: $(clang-tidy --version | sed -n 's/.*\(LLVM version [0-9.]*\).*/clang-tidy \1/p')"
    if ! CC=clang cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON -DRCAL_BUILD_TESTS=OFF \
        >"$BUILD_DIR.cfg.log" 2>&1; then
        cat "$BUILD_DIR.cfg.log"
        echo "static: configure for clang-tidy FAILED"
        exit 1
    fi
    rm -f "$BUILD_DIR.cfg.log"
    # generated sources the files include (egm.pb-c.h from firmware_host/egm.proto), when the build has them
    if grep -qx 'rcal_egm_pb' <(cmake --build "$BUILD_DIR" --target help 2>/dev/null | sed 's/^\.\.\. //'); then
        cmake --build "$BUILD_DIR" --target rcal_egm_pb >/dev/null 2>&1 || echo "static: note: rcal_egm_pb not built"
    fi
    tidy_out=$(mktemp)
    files=$(python3 -c '
import json, sys, re
root = sys.argv[1]
for e in json.load(open(sys.argv[2])):
    f = e["file"]
    if re.match(re.escape(root) + r"/(lib|tools|drivers|firmware_host)/", f):
        print(f)' "$ROOT" "$BUILD_DIR/compile_commands.json" | sort -u)
    nfiles=$(echo "$files" | wc -l)
    # one clang-tidy per file, JOBS at a time; output kept per file
    echo "$files" | xargs -P "$JOBS" -I{} sh -c 'clang-tidy -p "$1" --quiet "$2" 2>/dev/null; true' _ "$BUILD_DIR" {} \
        >"$tidy_out"
    # findings: "path:line:col: warning|error: text [check,...]"
    found=$(grep -E '^/[^ ]+:[0-9]+:[0-9]+: (warning|error): .*\[[^]]+\]$' "$tidy_out" | sort -u)
    left=""
    used=""
    while IFS= read -r line; do
        [ -n "$line" ] || continue
        file=${line%%:*}
        rel=${file#"$ROOT"/}
        checks=$(echo "$line" | sed 's/.*\[\([^]]*\)\]$/\1/' | tr ',' ' ')
        keep=1
        for c in $checks; do
            [[ $c == -* ]] && continue
            while read -r sid spath; do
                # shellcheck disable=SC2053
                if [[ $c == "$sid" && $rel == $spath ]]; then
                    keep=0
                    used+="$sid $spath"$'\n'
                fi
            done < <(supp_of tidy)
        done
        [ "$keep" = 1 ] && left+="$line"$'\n'
    done <<<"$found"
    nleft=$(printf '%s' "$left" | grep -c . || true)
    nsupp=$(printf '%s' "$found" | grep -c . || true)
    nsupp=$((nsupp - nleft))
    if [ "$nleft" -ne 0 ]; then
        printf '%s' "$left"
        echo "static: clang-tidy: $nleft finding(s) in $nfiles files FAILED"
        fail=1
    else
        echo "static: clang-tidy: 0 findings in $nfiles files ($nsupp suppressed by file, see $(basename "$SUPP"))"
    fi
    supp_of tidy | while read -r sid spath; do
        if ! grep -qxF "$sid $spath" <<<"$used"; then
            echo "static: note: stale clang-tidy suppression: $sid $spath"
        fi
    done
    rm -f "$tidy_out"
fi

echo "== static: $(($(date +%s) - start)) s"
if [ "$fail" -ne 0 ]; then
    echo "static analysis: FAILED"
    exit 1
fi
echo "static analysis: clean"
