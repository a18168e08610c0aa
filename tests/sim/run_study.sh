#!/bin/sh
# SPDX-License-Identifier: MIT
# Run truth_study.py with a python3 that has numpy (Debian's first), or skip (77).
for p in /usr/bin/python3 python3; do
  if "$p" -c 'import numpy' 2>/dev/null; then
    exec "$p" "$(dirname "$0")/truth_study.py" "$@"
  fi
done
echo 'SKIP: python3 with numpy not found (Debian package python3-numpy)'
exit 77
