#!/bin/sh
# SPDX-License-Identifier: MIT
# Run truth_study.py (or, with --script NAME first, another study of this
# directory) with a python3 that has numpy (Debian's first), or skip (77).
script=truth_study.py
if [ "$1" = "--script" ]; then
  script=$2
  shift 2
fi
for p in /usr/bin/python3 python3; do
  if "$p" -c 'import numpy' 2>/dev/null; then
    exec "$p" "$(dirname "$0")/$script" "$@"
  fi
done
echo 'SKIP: python3 with numpy not found (Debian package python3-numpy)'
exit 77
