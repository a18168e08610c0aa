#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# scripts/install_check.sh - rcal as a package, from a fresh tree (issue 15):
#  1. copy the tree as git sees it (tracked and new files, no build
#     directories) to a temporary place, configure, build and
#     `cmake --install` it into a temporary prefix (static libraries);
#  2. every installed header compiles on its own (C99, -pedantic), and only
#     the public ones are installed (docs/install.md "Public headers");
#     the manual pages and the bash completion are installed;
#     build examples/consumer against the installed tree twice, with
#     find_package(rcal CONFIG) and with a plain cc + pkg-config command line,
#     run both: they load irb120.json through the installed host library and
#     must print the same cable length;
#  3. the same with -DBUILD_SHARED_LIBS=ON: SONAMEs checked with readelf, both
#     consumers run against the shared libraries (and print the same length);
#  4. the installed `rcal --version` (its version, and the pinned reference
#     BLAS/LAPACK linked in; no installed library or consumer needs a shared
#     LAPACK or BLAS), then the source and build trees are
#     deleted, the prefix is copied elsewhere and the copy's `rcal calibrate
#     --data <copy>/share/rcal/sim_irb120.csv` must find its robot model under
#     the copy's share/rcal (run from / with RCAL_DATA_DIR unset), and must
#     fail when that directory is taken away.
# Environment: KEEP=1 keeps the temporary directory; JOBS (default nproc).
# Exit status 0 when every check passes.
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}
WORK=$(mktemp -d /tmp/rcal_install_check.XXXXXX)
if [ "${KEEP:-0}" = 1 ]; then
    echo "install_check: keeping $WORK"
else
    trap 'rm -rf "$WORK"' EXIT
fi
fail=0
ok() { echo "install_check: ok: $*"; }
bad() {
    echo "install_check: FAIL: $*" >&2
    fail=1
}

version=$(sed -n 's/^project(rcal VERSION \([0-9]*\.[0-9]*\.[0-9]*\).*/\1/p' "$ROOT/CMakeLists.txt")
major=${version%%.*}
minor=${version#*.}
minor=${minor%%.*}
if [ "$major" = 0 ]; then soversion=$major.$minor; else soversion=$major; fi

# ---- 1. a fresh tree --------------------------------------------------------
mkdir -p "$WORK/src"
if git -C "$ROOT" rev-parse --git-dir >/dev/null 2>&1; then
    (cd "$ROOT" && git ls-files -z --cached --others --exclude-standard |
        tar --null -T - --ignore-failed-read -cf - 2>/dev/null) | tar -xf - -C "$WORK/src"
else
    (cd "$ROOT" && tar --exclude='./build*' -cf - .) | tar -xf - -C "$WORK/src"
fi
echo "install_check: rcal $version from a fresh tree in $WORK/src"

build_install() { # name extra-cmake-args...
    local name=$1
    shift
    cmake -S "$WORK/src" -B "$WORK/build-$name" -DCMAKE_BUILD_TYPE=Release -DRCAL_BUILD_TESTS=OFF "$@" \
        >"$WORK/$name.log" 2>&1 &&
        cmake --build "$WORK/build-$name" -j"$JOBS" >>"$WORK/$name.log" 2>&1 &&
        cmake --install "$WORK/build-$name" --prefix "$WORK/$name" >>"$WORK/$name.log" 2>&1 ||
        {
            tail -n 30 "$WORK/$name.log" >&2
            return 1
        }
}

# consumer_both name pkg-config-flag extra-ld-flag: builds the consumer both
# ways against prefix $WORK/name, runs them, prints the common output line.
consumer_both() {
    local name=$1 prefix=$WORK/$1 pcflag=$2 ldflag=$3
    local out_cmake out_pc
    if ! cmake -S "$WORK/src/examples/consumer" -B "$WORK/consumer-$name" -DCMAKE_BUILD_TYPE=Release \
        -DCMAKE_PREFIX_PATH="$prefix" >"$WORK/consumer-$name.log" 2>&1 ||
        ! cmake --build "$WORK/consumer-$name" >>"$WORK/consumer-$name.log" 2>&1; then
        tail -n 30 "$WORK/consumer-$name.log" >&2
        bad "$name: consumer with find_package does not build"
        return 1
    fi
    out_cmake=$("$WORK/consumer-$name/consumer" "$prefix/share/rcal/irb120.json") ||
        { bad "$name: consumer (find_package) failed"; return 1; }
    # shellcheck disable=SC2046
    if ! cc -std=c99 -Wall -Wextra -Werror -pedantic "$WORK/src/examples/consumer/consumer.c" \
        $(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --cflags --libs $pcflag rcal) $ldflag \
        -o "$WORK/consumer-$name/consumer_pc"; then
        bad "$name: consumer with pkg-config does not build"
        return 1
    fi
    out_pc=$("$WORK/consumer-$name/consumer_pc" "$prefix/share/rcal/irb120.json") ||
        { bad "$name: consumer (pkg-config) failed"; return 1; }
    printf 'install_check: %s find_package: %s\ninstall_check: %s pkg-config:   %s\n' \
        "$name" "$out_cmake" "$name" "$out_pc" >"$WORK/consumer-$name.out"
    if [ "$out_cmake" != "$out_pc" ] || [[ $out_cmake != *"cable length"* ]]; then
        bad "$name: the two consumers disagree"
        return 1
    fi
    echo "$out_cmake"
}

# ---- 2. static libraries ----------------------------------------------------
t0=$(date +%s)
if build_install static; then
    ok "static build and install ($(($(date +%s) - t0)) s): $(cd "$WORK/static" && ls lib/*.a | tr '\n' ' ')"
    for f in lib/cmake/rcal/rcalConfig.cmake lib/cmake/rcal/rcalConfigVersion.cmake lib/pkgconfig/rcal.pc \
        include/rcal/rc_version.h include/rcal/rch_robot.h share/rcal/irb120.json share/doc/rcal/LICENSE \
        share/man/man1/rcal.1 share/man/man1/rcal-calibrate.1 share/bash-completion/completions/rcal; do
        [ -f "$WORK/static/$f" ] || bad "static: $f not installed"
    done
    # every installed header compiles on its own (C99, -pedantic, -Werror)
    nh=0
    for h in "$WORK/static/include/rcal"/*.h; do
        nh=$((nh + 1))
        printf '#include "%s"\n' "$(basename "$h")" >"$WORK/header.c"
        cc -std=c99 -Wall -Wextra -Werror -pedantic -fsyntax-only -I"$WORK/static/include/rcal" "$WORK/header.c" ||
            bad "static: installed header $(basename "$h") does not compile on its own"
    done
    ok "static: $nh installed headers compile on their own"
    host=$(sed -n 's/^public host headers: //p' "$WORK/src/docs/install.md" | tr -d '`,' | tr ' ' '\n' | grep . | sort)
    want=$( (cd "$WORK/src/lib" && ls rc_*.h) | cat - <(echo rc_version.h) <(echo "$host") | sort -u)
    [ "$(cd "$WORK/static/include/rcal" && ls)" = "$want" ] && ok "static: only the public headers are installed" ||
        bad "static: the installed headers differ from docs/install.md's public set"
    static_out=$(consumer_both static --static "") && cat "$WORK/consumer-static.out" &&
        ok "static: the two consumers print the same length"
else
    bad "static build/install"
fi

# ---- 3. shared libraries ----------------------------------------------------
t0=$(date +%s)
if build_install shared -DBUILD_SHARED_LIBS=ON; then
    ok "shared build and install ($(($(date +%s) - t0)) s)"
    for lib in rcalcore rcalhost; do
        so=$(readelf -d "$WORK/shared/lib/lib$lib.so" 2>/dev/null | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
        if [ "$so" = "lib$lib.so.$soversion" ] && [ -f "$WORK/shared/lib/lib$lib.so.$version" ]; then
            ok "shared: SONAME $so (lib$lib.so.$version)"
        else
            bad "shared: lib$lib.so has SONAME '$so', want lib$lib.so.$soversion"
        fi
    done
    # (the plain cc build gets an rpath: the prefix is not in the loader's path)
    shared_out=$(consumer_both shared "" "-Wl,-rpath,$WORK/shared/lib") || true
    if [ -n "${shared_out:-}" ]; then
        cat "$WORK/consumer-shared.out"
        if readelf -d "$WORK/consumer-shared/consumer_pc" | grep -q "librcalhost.so.$soversion"; then
            ok "shared: consumers run against librcalhost.so.$soversion"
        else
            bad "shared: the pkg-config consumer is not linked with the shared host library"
        fi
        [ "$shared_out" = "${static_out:-}" ] && ok "shared and static consumers print the same length" ||
            bad "shared and static consumers differ"
    fi
else
    bad "shared build/install"
fi

# ---- 4. the installed program and its data ----------------------------------
for kind in static shared; do
    [ -x "$WORK/$kind/bin/rcal" ] || continue
    v=$("$WORK/$kind/bin/rcal" --version | head -n 1)
    [ "$v" = "rcal $version" ] && ok "$kind: rcal --version: $v" || bad "$kind: rcal --version says '$v'"
    # the commit it was built from: "unknown" here (the fresh tree is a copy, not a git checkout)
    c=$("$WORK/$kind/bin/rcal" --version | sed -n 's/^commit: //p')
    [ "$c" = unknown ] && ok "$kind: rcal --version: commit: $c (built outside git)" ||
        bad "$kind: rcal --version says commit '$c', want 'unknown' for a tree outside git"
    # the pinned reference LAPACK and BLAS (cmake/rcal_lapack.cmake), linked in
    la=$("$WORK/$kind/bin/rcal" --version | sed -n 's/^BLAS\/LAPACK: //p')
    [[ $la == "reference LAPACK "*" and BLAS, linked in (pinned: "* ]] && ok "$kind: BLAS/LAPACK: $la" ||
        bad "$kind: rcal --version says BLAS/LAPACK '$la', want the pinned reference, linked in"
done
# nothing installed or built against the package takes LAPACK or BLAS from the
# loader (where an alternative would switch it): the shared host library and
# both consumers have them inside
for f in "$WORK/shared/lib/librcalhost.so" "$WORK/consumer-static/consumer" "$WORK/consumer-static/consumer_pc" \
    "$WORK/consumer-shared/consumer" "$WORK/consumer-shared/consumer_pc"; do
    [ -f "$f" ] || continue
    needed=$(readelf -d "$f" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | grep -E '^lib(lapack|lapacke|blas|openblas|atlas)' || true)
    [ -z "$needed" ] && ok "${f#"$WORK"/}: no shared LAPACK/BLAS needed (the reference archives linked in)" ||
        bad "${f#"$WORK"/}: needs $needed from the loader"
done
# reference figures: the build tree's rcal on the source tree's data
ref=""
if [ -x "$WORK/build-static/tools/rcal" ]; then
    ref=$("$WORK/build-static/tools/rcal" calibrate --data "$WORK/src/data/sim_irb120.csv" 2>&1 |
        grep -v -e '^rcal calibrate:' -e '^solver:') || ref=""
fi
rm -rf "$WORK/src" "$WORK"/build-* # nothing left to fall back on
for kind in static shared; do
    [ -x "$WORK/$kind/bin/rcal" ] || continue
    moved=$WORK/moved-$kind
    cp -a "$WORK/$kind" "$moved"
    rm -rf "$WORK/$kind"
    robot=$(cd / && env -u RCAL_DATA_DIR "$moved/bin/rcal" --version | sed -n 's/^robot model: //p')
    [ "$robot" = "$moved/share/rcal/irb120.json" ] && ok "$kind (copied prefix): robot model $robot" ||
        bad "$kind (copied prefix): robot model '$robot'"
    if out=$(cd / && env -u RCAL_DATA_DIR "$moved/bin/rcal" calibrate --data "$moved/share/rcal/sim_irb120.csv" 2>&1) &&
        [[ $out == *'robot "ABB IRB120'* ]]; then
        ok "$kind (copied prefix): rcal calibrate, held-out RMSE mean|e| SD MAX (mm)$(echo "$out" | grep -m1 '^  after' | sed 's/  */ /g')"
        if [ -n "$ref" ] && [ "$(echo "$out" | grep -v -e '^rcal calibrate:' -e '^solver:')" = "$ref" ]; then
            ok "$kind (copied prefix): the figures equal those of the build tree"
        else
            bad "$kind (copied prefix): the figures differ from those of the build tree"
        fi
    else
        echo "$out" | tail -n 5 >&2
        bad "$kind (copied prefix): rcal calibrate did not find its robot model"
    fi
    mv "$moved/share/rcal" "$moved/share/rcal.away"
    if (cd / && env -u RCAL_DATA_DIR "$moved/bin/rcal" calibrate --data "$moved/share/rcal.away/sim_irb120.csv" \
        >/dev/null 2>&1); then
        bad "$kind (copied prefix): rcal calibrate ran without share/rcal (a model from elsewhere?)"
    else
        ok "$kind (copied prefix): without share/rcal the model is not found (no other place is used)"
    fi
done

if [ $fail = 0 ]; then echo "install_check: all checks passed"; else echo "install_check: FAILED" >&2; fi
exit $fail
