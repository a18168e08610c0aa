#!/bin/sh
# SPDX-License-Identifier: MIT
# The host library's layers: tools/host/<layer>/, each using only the layers
# before it (files <- model <- comp <- fit <- studies <- outputs). A file including a
# header of a later layer is a circle in the making: this prints each such
# include and exits 1; also any SVG markup written outside files/rch_svg.c
# (the one SVG writer). Usage: scripts/layers.sh [SOURCE_DIR]
set -eu
root=${1:-$(dirname "$0")/..}
host=$root/tools/host
layers="files model comp fit studies outputs"
rank() { i=0; for l in $layers; do [ "$l" = "$1" ] && { echo $i; return; }; i=$((i + 1)); done; echo 99; }
map=$(mktemp)
trap 'rm -f "$map"' EXIT
for l in $layers; do
  for h in "$host/$l"/*.h; do echo "$(basename "$h") $l"; done
done >"$map"
# every file in a layer directory; none left at the top
bad=0
for f in "$host"/*.c "$host"/*.h; do
  [ -e "$f" ] || continue
  echo "layers: $f is in no layer (move it into one of: $layers)"; bad=1
done
n=0
for l in $layers; do
  r=$(rank "$l")
  for f in "$host/$l"/*.c "$host/$l"/*.h; do
    n=$((n + 1))
    for inc in $(sed -n 's/^#include "\(rch_[a-z0-9_]*\.h\)".*/\1/p' "$f"); do
      t=$(awk -v h="$inc" '$1 == h { print $2 }' "$map")
      if [ -z "$t" ]; then echo "layers: $f includes $inc, found in no layer"; bad=1; continue; fi
      if [ "$(rank "$t")" -gt "$r" ]; then
        echo "layers: $f ($l) includes $inc of the later layer $t"; bad=1
      fi
    done
  done
done
# one writer of SVG markup: no string literal outside files/rch_svg.c opens an SVG element
svg_re='"([^"\\]|\\.)*<(svg|g|rect|circle|line|path|polyline|polygon|clipPath|defs|text)[ >/\\"]'
for f in $(find "$root/tools" "$root/lib" "$root/drivers" "$root/firmware_host" -name '*.[ch]' ! -name rch_svg.c); do
  hits=$(grep -nE "$svg_re" "$f" | grep -vE '^[0-9]+:[[:space:]]*(/?\*|//)' || true)
  if [ -n "$hits" ]; then
    echo "layers: $f writes SVG markup itself (draw through files/rch_svg.h):"; printf "%s\n" "$hits" | head -3; bad=1
  fi
done
[ $bad -eq 0 ] && echo "layers: $n files, every include from its own or an earlier layer ($layers); SVG markup only in files/rch_svg.c"
exit $bad
