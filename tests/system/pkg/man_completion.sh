#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# tests/system/pkg/man_completion.sh RCAL MANDIR - the manual pages and the bash
# completion the build writes from the option tables (cmake/rcal_man.cmake;
# ctest pkg_man_completion), checked against what --help prints:
#  - rcal --help-commands names the commands `rcal --help` lists; rcal.1
#    exists and names rcal-CMD(1) for each; every rcal-CMD.1 exists;
#  - every option `rcal CMD --help` lists is in the rendered page
#    (groff -man -Tascii, as man shows it) and the page's option entries are
#    exactly those (no stale option);
#  - the completion script registers itself (complete -p rcal); completing
#    the first word offers every command; `rcal CMD --` offers exactly the
#    options --help lists; after an option with choices (its value shown as
#    a|b|c) it offers exactly those choices, also as --name=VALUE.
# Exit 0 when all hold, 1 with each failure named; 77 without groff.
set -uo pipefail
RCAL=$1
MAN=$2
fail=0
bad() {
    echo "pkg_man_completion: FAIL: $*"
    fail=1
}
command -v groff >/dev/null || {
    echo "pkg_man_completion: SKIPPED: no groff (Debian: groff-base)"
    exit 77
}
render() { groff -man -Tascii -P-cbou "$1" 2>/dev/null; }
COMP=$MAN/bash-completion/rcal
[ -f "$COMP" ] || bad "no completion script $COMP"
# complete WORD...: the completion's offers for the command line "WORD..." (the
# last word is the one completed), one per line, sorted
complete_words() {
    bash -c 'source "$1"; shift; COMP_WORDS=("$@"); COMP_CWORD=$((${#COMP_WORDS[@]} - 1)); COMPREPLY=(); _rcal
             printf "%s\n" "${COMPREPLY[@]}" | sort' _ "$COMP" "$@"
}

cmds=$("$RCAL" --help-commands) || bad "rcal --help-commands failed"
listed=$("$RCAL" --help | sed -n 's/^  \([a-z][a-z0-9-]*\) .*/\1/p')
[ "$(sort <<<"$cmds")" = "$(sort <<<"$listed")" ] || bad "--help-commands ($cmds) differs from rcal --help ($listed)"
[ -f "$MAN/man1/rcal.1" ] || bad "no rcal.1"
top=$(render "$MAN/man1/rcal.1")
reg=$(bash -c 'source "$1" && complete -p rcal' _ "$COMP" 2>&1)
[[ $reg == "complete "*"-F _rcal"*" rcal" ]] || bad "the script does not register _rcal for rcal: '$reg'"
first=$(complete_words rcal "")
[ "$first" = "$(printf '%s\n' $cmds --help --version | sort)" ] || bad "rcal <TAB> offers: $(echo $first)"
[ "$(complete_words rcal cal)" = calibrate ] || bad "rcal cal<TAB> does not complete to calibrate"

n_cmd=0 n_opt=0 n_choice=0
for c in $cmds; do
    n_cmd=$((n_cmd + 1))
    grep -q "rcal-$c(1)" <<<"$top" || bad "rcal.1 does not name rcal-$c(1)"
    page=$MAN/man1/rcal-$c.1
    [ -f "$page" ] || { bad "no $page"; continue; }
    text=$(render "$page")
    help=$("$RCAL" "$c" --help)
    opts=$(sed -n 's/^  \(--[a-z0-9-]*\).*/\1/p' <<<"$help")
    [ -n "$opts" ] || bad "$c: --help lists no option"
    for o in $opts; do
        n_opt=$((n_opt + 1))
        grep -qE "^ +$o( |$)" <<<"$text" || bad "$c: $o (in --help) is not an entry of rcal-$c(1)"
    done
    grep -qE "^ +-h, --help" <<<"$text" || bad "$c: -h, --help is not in rcal-$c(1)"
    # the page's entries: the .TP heads of its source
    entries=$(sed -n '/^\.TP$/{n;s/^\\fB\(\\-\\-[a-z0-9\\-]*\)\\fR.*/\1/p}' "$page" | sed 's/\\-/-/g' | sort)
    [ "$entries" = "$(sort <<<"$opts")" ] || bad "$c: the page's options differ from --help: $(diff <(echo "$entries") <(sort <<<"$opts") | tr '\n' ' ')"
    offered=$(complete_words rcal "$c" --)
    [ "$offered" = "$(printf '%s\n' $opts --help | sort)" ] || bad "$c: rcal $c --<TAB> offers $(echo $offered)"
    # options whose value is a list of choices
    while read -r o arg; do
        [[ $arg =~ ^[a-z0-9.-]+(\|[a-z0-9.-]+)+$ ]] || continue
        n_choice=$((n_choice + 1))
        want=$(tr '|' '\n' <<<"$arg" | sort)
        got=$(complete_words rcal "$c" "$o" "")
        [ "$got" = "$want" ] || bad "$c: rcal $c $o <TAB> offers '$(echo $got)', want '$(echo $want)'"
        got=$(complete_words rcal "$c" "$o" "=" "")
        [ "$got" = "$want" ] || bad "$c: rcal $c $o=<TAB> offers '$(echo $got)', want '$(echo $want)'"
    done < <(sed -n 's/^  \(--[a-z0-9-]*\) \([^ ]*\) .*/\1 \2/p' <<<"$help")
done
[ "$n_choice" -gt 0 ] || bad "no option with choices found (the --help format changed?)"
[ "$fail" = 0 ] && echo "pkg_man_completion: $n_cmd commands, $n_opt options in their pages and completion, $n_choice options' choices completed"
exit $fail
