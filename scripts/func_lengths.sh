#!/bin/sh
# SPDX-License-Identifier: MIT
# scripts/func_lengths.sh - the longest C functions, in lines (issue 15: no
# command function longer than about 80 lines).
#
# Usage: scripts/func_lengths.sh [-n N] [FILE...]
# Prints "lines file:line name", longest first, N rows (default 10); without
# files, every .c file git tracks. A function counts from its opening '{' in
# column 0 to its closing '}' in column 0, both included (the project's
# style puts both there); its name is the identifier before the first '(' of
# the signature above the brace, and file:line is where that signature starts.
n=10
if [ "$1" = "-n" ]; then
    n=$2
    shift 2
fi
# shellcheck disable=SC2016 # an awk program: its $ are awk's
prog='
FNR == 1 { sig = ""; start = 0 }
/^[A-Za-z_].*\(/ && start == 0 { sig = $0; sigline = FNR }
/^\{/ && start == 0 && sig != "" {
    start = FNR
    name = sig; sub(/\(.*/, "", name); sub(/.*[ *]/, "", name)
    next
}
/^\}/ && start > 0 {
    printf "%d %s:%d %s\n", FNR - start + 1, FILENAME, sigline, name
    start = 0; sig = ""
}
/^[;}]|^$/ && start == 0 { sig = "" }
'
if [ $# -eq 0 ]; then
    cd "$(dirname "$0")/.." || exit 1
    git ls-files -z '*.c' | xargs -0 awk "$prog"
else
    awk "$prog" "$@"
fi | sort -k1,1nr | head -n "$n"
