# SPDX-License-Identifier: MIT
"""rcal._check - the arguments' validation of the Python API: shapes, dtypes,
finite values and labels checked as the CLI's readers check them, each
failure a ValueError naming the argument, the expected shape and the row."""
import ctypes
import math

try:  # optional
    import numpy as _np
except ImportError:  # pragma: no cover - depends on the machine
    _np = None


def _ints(values, n, what, hi):
    """Labels (n integers in 0..hi) -> a ctypes int array; ValueError naming
    the argument for a wrong length, a non-integer or a label out of range
    (the CSV reader's limits: group 0..65535, outlet 0..255)."""
    if values is None:
        return None
    if _np is not None and isinstance(values, _np.ndarray):
        if values.ndim != 1:
            raise ValueError("%s: expected shape (%d,), got shape %s" % (what, n, values.shape))
        if values.dtype.kind not in "iuf":
            raise ValueError("%s: expected integer labels, got dtype %s" % (what, values.dtype))
        values = values.tolist()
    elif isinstance(values, (str, bytes)) or not hasattr(values, "__len__"):
        raise ValueError("%s: expected a sequence of %d integer labels" % (what, n))
    vals = []
    for k, v in enumerate(values):
        if not _real(v):
            raise ValueError("%s: sample %d: %r is not an integer label" % (what, k, v))
        f = float(v)
        if not math.isfinite(f) or f != math.floor(f) or f < 0 or f > hi:
            raise ValueError("%s: sample %d: %r is not an integer in 0..%d" % (what, k, v, hi))
        vals.append(int(f))
    if len(vals) != n:
        raise ValueError("%s: %d values for %d samples, expected shape (%d,)" % (what, len(vals), n, n))
    return (ctypes.c_int * max(n, 1))(*vals)


def _shape_text(width):
    return "(%d,) or (n, %d)" % (width, width) if width > 1 else "(n,)"


def _finite_flat(flat, width, what):
    for k, v in enumerate(flat):
        if not math.isfinite(v):
            raise ValueError("%s: %s at %s is not finite (NaN or infinity refused)"
                             % (what, v, ("row %d, column %d" % (k // width, k % width)) if width > 1
                                else "sample %d" % k))


def _doubles(values, width, what):
    """Rows of `width` numbers -> (ctypes double array, n, single, numpy).
    single: the input was one row (width numbers) rather than a batch.
    Accepted shapes: (width,) one row, (n, width) a batch; for width 1,
    (n,) (and a plain number, single). Anything else, a non-numeric dtype or
    a non-finite value raises ValueError naming the argument and the
    expected shape."""
    if _np is not None and isinstance(values, _np.ndarray):
        if values.dtype.kind not in "iuf":
            raise ValueError("%s: expected real numbers (float or int dtype), got dtype %s" % (what, values.dtype))
        a = _np.ascontiguousarray(values, dtype=_np.float64)
        if width > 1:
            ok = (a.ndim == 1 and a.shape[0] == width) or (a.ndim == 2 and a.shape[1] == width)
            single = a.ndim == 1
        else:
            ok = a.ndim <= 1
            single = a.ndim == 0
        if not ok:
            raise ValueError("%s: expected shape %s, got shape %s" % (what, _shape_text(width), values.shape))
        a = a.reshape(-1, width) if width > 1 else a.reshape(-1)
        if not _np.all(_np.isfinite(a)):
            _finite_flat(a.reshape(-1).tolist(), width, what)  # raises
        n = a.shape[0]
        buf = (ctypes.c_double * max(a.size, 1))()
        ctypes.memmove(buf, a.ctypes.data, a.size * 8)
        return buf, n, single, True
    if isinstance(values, (str, bytes)):
        raise ValueError("%s: expected numbers of shape %s, got a string" % (what, _shape_text(width)))
    if _real(values):
        if width > 1:
            raise ValueError("%s: expected shape %s, got one number" % (what, _shape_text(width)))
        rows = [values]
    else:
        rows = list(values)
    if width > 1:
        single = len(rows) > 0 and all(_real(v) for v in rows)
        if single and len(rows) != width:
            raise ValueError("%s: expected shape %s, got %d numbers in one flat list (give n rows of %d)"
                             % (what, _shape_text(width), len(rows), width))
        if single:
            rows = [rows]
        flat = []
        for k, row in enumerate(rows):
            if _real(row) or isinstance(row, (str, bytes)):
                raise ValueError("%s: row %d is %r, expected %d numbers (shape %s)"
                                 % (what, k, row, width, _shape_text(width)))
            row = list(row)
            if len(row) != width or not all(_real(v) for v in row):
                raise ValueError("%s: row %d has %d values, expected %d numbers (shape %s)"
                                 % (what, k, len(row), width, _shape_text(width)))
            flat.extend(float(v) for v in row)
    else:
        single = _real(values)
        for k, v in enumerate(rows):
            if not _real(v):
                raise ValueError("%s: sample %d is %r, expected a number (shape (n,))" % (what, k, v))
        flat = [float(v) for v in rows]
    _finite_flat(flat, width, what)
    n = len(flat) // width
    buf = (ctypes.c_double * max(len(flat), 1))(*flat)
    return buf, n, single, False


def _real(v):
    """A real number (int, float or a numpy real scalar; not a bool)."""
    if isinstance(v, bool) or (_np is not None and isinstance(v, _np.bool_)):
        return False
    return isinstance(v, (int, float)) or (_np is not None and isinstance(v, (_np.integer, _np.floating)))


def _is_scalar(v):
    return _np is not None and isinstance(v, _np.generic)


def _rows(buf, n, width, single, numpy):
    """ctypes array of n rows -> a tuple (single), a list of tuples, or numpy."""
    if numpy:
        a = _np.ctypeslib.as_array(buf)[:n * width].copy()
        a = a.reshape(n, width) if width > 1 else a
        return a[0] if single else a
    if width == 1:
        vals = list(buf[:n])
        return vals[0] if single else vals
    out = [tuple(buf[width * i:width * (i + 1)]) for i in range(n)]
    return out[0] if single else out
