#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# tests/system/pkg/colcon_package.sh SOURCE VERSION - package.xml (ctest
# pkg_colcon_package): a ROS package of format 3 whose build type is plain
# cmake, named rcal, at the project's VERSION, valid for catkin_pkg (the
# parser colcon-ros and rosdep read it with: parse_package + validate), and
# identified by colcon as a ros.cmake package (`colcon list`). Each check runs
# when its tool is installed (Debian: python3-catkin-pkg, colcon with
# python3-colcon-ros; scripts/install-deps.sh), xmllint's well-formedness
# otherwise; 77 when none is. A whole `colcon build` takes minutes: measured
# by hand (docs/install.md), not here.
set -uo pipefail
SRC=$1
VERSION=$2
fail=0
checks=0
bad() {
    echo "pkg_colcon_package: FAIL: $*"
    fail=1
}
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
if "$PY" -c 'import catkin_pkg' 2>/dev/null; then
    checks=$((checks + 1))
    out=$("$PY" - "$SRC" <<'PYEOF' 2>&1
import sys
from catkin_pkg.package import parse_package
p = parse_package(sys.argv[1])
p.validate()
bt = [e.content for e in p.exports if e.tagname == "build_type"]
print(p.name, p.version, p.package_format, ",".join(bt), p.licenses[0] if p.licenses else "")
PYEOF
    ) || bad "catkin_pkg refuses package.xml: $out"
    [ "$out" = "rcal $VERSION 3 cmake MIT" ] && echo "pkg_colcon_package: catkin_pkg: name, version, format, build type, licence: $out" ||
        bad "catkin_pkg reads '$out', want 'rcal $VERSION 3 cmake MIT' (the version is project(rcal VERSION ...))"
elif command -v xmllint >/dev/null; then
    checks=$((checks + 1))
    xmllint --noout "$SRC/package.xml" || bad "package.xml is not well-formed XML"
    grep -q '<package format="3">' "$SRC/package.xml" || bad "not <package format=\"3\">"
    grep -q "<version>$VERSION</version>" "$SRC/package.xml" || bad "its version is not $VERSION"
    grep -q '<build_type>cmake</build_type>' "$SRC/package.xml" || bad "its build type is not cmake"
fi
if command -v colcon >/dev/null; then
    checks=$((checks + 1))
    tmp=$(mktemp -d /tmp/rcal_colcon.XXXXXX)
    trap 'rm -rf "$tmp"' EXIT
    out=$(cd "$tmp" && colcon --log-base /dev/null list --base-paths "$SRC" 2>&1)
    [ "$(printf '%s' "$out" | cut -f1,3)" = "rcal	(ros.cmake)" ] && echo "pkg_colcon_package: colcon list: $out" ||
        bad "colcon list says '$out', want rcal as (ros.cmake)"
fi
if [ "$checks" = 0 ]; then
    echo "pkg_colcon_package: SKIPPED: neither catkin_pkg, xmllint nor colcon is installed"
    exit 77
fi
exit $fail
