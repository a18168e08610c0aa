#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# tests/system/pkg/public_headers.sh BUILD SOURCE CC - the installed API (ctest
# pkg_public_headers): `cmake --install BUILD` into a temporary prefix, then
#  - include/rcal/ holds exactly the public headers: the core's lib/rc_*.h,
#    the generated rc_version.h and the host headers docs/install.md lists
#    under "Public headers" (its line `public host headers: ...`), no other;
#  - each compiles alone with `CC -std=c99 -pedantic -Werror -fsyntax-only`
#    against that directory only (so the public set is closed under its own
#    #includes), and with -Wall -Wextra too.
# Exit 0 when all hold, 1 naming each failure.
set -uo pipefail
BUILD=$1
SRC=$2
CC=$3
fail=0
bad() {
    echo "pkg_public_headers: FAIL: $*"
    fail=1
}
tmp=$(mktemp -d /tmp/rcal_public_headers.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$BUILD" --prefix "$tmp/prefix" >"$tmp/install.log" 2>&1 || {
    tail -n 20 "$tmp/install.log"
    bad "cmake --install $BUILD"
    exit 1
}
inc=$tmp/prefix/include/rcal
host=$(sed -n 's/^public host headers: //p' "$SRC/docs/install.md" | tr -d '`,' | tr ' ' '\n' | grep . | sort)
[ -n "$host" ] || bad "docs/install.md has no line 'public host headers: ...'"
want=$( (cd "$SRC/lib" && ls rc_*.h) | cat - <(echo rc_version.h) <(echo "$host") | sort -u)
got=$(cd "$inc" && ls)
[ "$got" = "$want" ] || bad "installed headers differ from the documented public set: $(diff <(echo "$want") <(echo "$got") | grep '^[<>]' | tr '\n' ' ')"
n=0
for h in "$inc"/*; do
    n=$((n + 1))
    printf '#include "%s"\n' "$(basename "$h")" >"$tmp/one.c"
    "$CC" -std=c99 -pedantic -Werror -fsyntax-only -I"$inc" "$tmp/one.c" ||
        bad "$(basename "$h") does not compile alone (-std=c99 -pedantic -Werror)"
    "$CC" -std=c99 -pedantic -Wall -Wextra -Werror -fsyntax-only -I"$inc" "$tmp/one.c" ||
        bad "$(basename "$h") does not compile alone with -Wall -Wextra"
done
[ "$fail" = 0 ] && echo "pkg_public_headers: $n installed headers, exactly the public set, each compiles alone: $(echo $got)"
exit $fail
