#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# python/tests/no_lapack_machine.sh LIB PYTHON3 - ctest python_no_lapack:
# rcal.calibrate through LIB (librcal_ffi.so) on a machine where no LAPACK,
# BLAS or Fortran run-time can be loaded: in a private mount namespace
# (unshare -m, root) the reference and alternative LAPACK/BLAS directories
# are emptied (tmpfs over <libdir>/lapack, blas, atlas, openblas*) and every
# liblapack*, libblas*, liblapacke*, libgfortran*, libquadmath*, libopenblas*,
# libatlas* of the library directories is replaced by /dev/null (unloadable).
# The demo calibration must give the figures it gives on the full machine.
# 77 when a mount namespace cannot be made (not root, no CAP_SYS_ADMIN).
set -uo pipefail
LIB=$(readlink -f "$1")
PY=$2
SRC=$(cd "$(dirname "$0")/../.." && pwd)
unshare -m true 2>/dev/null || {
    echo "python_no_lapack: SKIPPED: cannot make a mount namespace (unshare -m; needs root)"
    exit 77
}
probe='
import sys, rcal
r = rcal.calibrate(sys.argv[1])
print("%d %d %.10f %.10f" % (r.before.n, r.after.n, r.before.rmse_mm, r.after.rmse_mm))
'
full=$(cd "$SRC" && RCAL_FFI_LIB=$LIB PYTHONPATH=$SRC/python "$PY" -c "$probe" data/sim_irb120.csv 2>/dev/null) || {
    echo "python_no_lapack: FAIL: the calibration does not run on the full machine"
    exit 1
}
bare=$(cd "$SRC" && RCAL_FFI_LIB=$LIB PYTHONPATH=$SRC/python unshare -m bash -c '
    set -e
    n=0
    for d in /usr/lib/*-linux-gnu /lib/*-linux-gnu /usr/lib /usr/lib64 /usr/local/lib; do
        [ -d "$d" ] || continue
        for s in "$d"/lapack "$d"/blas "$d"/atlas "$d"/openblas*; do
            [ -d "$s" ] && mount -t tmpfs none "$s" && n=$((n + 1))
        done
        for f in "$d"/liblapack* "$d"/libblas* "$d"/libgfortran* "$d"/libquadmath* "$d"/libopenblas* "$d"/libatlas* "$d"/libcblas*; do
            [ -f "$f" ] && mount --bind /dev/null "$f" && n=$((n + 1))
        done
    done
    echo "python_no_lapack: $n directories and files made unloadable" >&2
    if "$0" -c "import ctypes.util, ctypes; ctypes.CDLL(\"libgfortran.so.5\")" 2>/dev/null; then
        echo "python_no_lapack: libgfortran.so.5 still loads" >&2; exit 3
    fi
    "$0" -c "$1" data/sim_irb120.csv
' "$PY" "$probe")
rc=$?
if [ $rc -ne 0 ]; then
    echo "python_no_lapack: FAIL: rcal.calibrate does not run without LAPACK/BLAS/gfortran on the machine (exit $rc)"
    exit 1
fi
echo "python_no_lapack: full machine: n before/after, RMSE before/after (mm): $full"
echo "python_no_lapack: no LAPACK/BLAS/gfortran:                            $bare"
[ "$full" = "$bare" ] || {
    echo "python_no_lapack: FAIL: the figures differ"
    exit 1
}
echo "python_no_lapack: passed"
