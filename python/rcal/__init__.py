# SPDX-License-Identifier: MIT
"""rcal: robot calibration with a cable encoder, from Python.

A thin ctypes layer over the C libraries of this repository (the flat API of
tools/host/outputs/rch_ffi.h in librcal_ffi.so), so every figure is the one the
command-line tool prints: the calibration runs the same host function as
`rcal calibrate`, the compensation the same stream as `rcal compensate`.

Units: joint angles in DEGREES, lengths in MILLIMETRES, everywhere.
Arrays: a pose is 6 numbers (q1..q6); a batch is n poses, as a list of lists
or an (n, 6) numpy array. Results come back as tuples and lists, or as numpy
arrays when the input was a numpy array (numpy is optional).

    import rcal
    m = rcal.Model.load("data/irb120.json")
    x, y, z = m.fk([0, 0, 0, 0, 30, 0])                       # mm
    r = rcal.calibrate(data_csv="data/sim_irb120.csv")        # data/irb120.json by default
    print(r.before.rmse_mm, r.after.rmse_mm)
    r.write("cal.json")
    q_new = rcal.compensate(rcal.Model.load("cal.json"), [[10, 20, 30, 0, 40, 0]])

Errors raise RcalError with the C library's message ("file:line:col: ...").
"""

import collections
import ctypes
import os

from . import _lib

__all__ = ["RcalError", "Model", "Metrics", "Param", "Result", "calibrate", "compensate", "default_robot"]

try:  # optional
    import numpy as _np
except ImportError:  # pragma: no cover - depends on the machine
    _np = None

_ERR_LEN = 1024

Metrics = collections.namedtuple("Metrics", "n rmse_mm mean_abs_mm sd_mm mean_mm max_mm")
Metrics.__doc__ = """Cable-length error over a sample set, mm (n: number of samples; mean_abs_mm is
what the paper's Eq. 20 calls SD, sd_mm the true standard deviation)."""

Param = collections.namedtuple("Param", "name unit value delta")
Param.__doc__ = """One identified parameter as `rcal calibrate --json` lists it: unit "mm", "deg"
or "-"; value and delta against nominal in that unit (the encoder's delta is
against the before-calibration fit)."""

_UNITS = {0: "mm", 1: "deg", 2: "-"}


class RcalError(Exception):
    """A failure reported by the C library. status: the rch_ffi_status code
    (negative), kind: its name ("bad input file", ...), message: the library's
    diagnostic ("file:line:col: message" for an input file)."""

    def __init__(self, status, message):
        self.status = status
        self.kind = _lib.lib().rch_ffi_strerror(status).decode()
        self.message = message
        super().__init__(message if message else self.kind)


def _check(status, err=None):
    if status != 0:
        raise RcalError(status, err.value.decode(errors="replace") if err is not None else "")


def _path(p):
    return os.fsencode(os.fspath(p))


def _opt_path(p):
    return None if p is None else _path(p)


def default_robot():
    """Path of the nominal robot model `rcal` uses by default (data/irb120.json:
    $RCAL_DATA_DIR/irb120.json when that variable is set, else the
    repository's data/)."""
    d = os.environ.get("RCAL_DATA_DIR")
    return os.path.join(d if d else os.path.join(_lib.repo_root(), "data"), "irb120.json")


def _doubles(values, width, what):
    """Rows of `width` numbers -> (ctypes double array, n, single, numpy).
    single: the input was one row (width numbers) rather than a batch."""
    if _np is not None and isinstance(values, _np.ndarray):
        a = _np.ascontiguousarray(values, dtype=_np.float64)
        single = (a.ndim == 1 and width > 1) or a.ndim == 0
        if a.size % width or (a.ndim == 2 and a.shape[1] != width) or a.ndim > 2:
            raise ValueError("%s: expected rows of %d numbers, got shape %s" % (what, width, values.shape))
        a = a.reshape(-1, width) if width > 1 else a.reshape(-1)
        n = a.shape[0]
        buf = (ctypes.c_double * max(a.size, 1))()
        ctypes.memmove(buf, a.ctypes.data, a.size * 8)
        return buf, n, single, True
    rows = list(values) if not isinstance(values, (int, float)) else [values]
    if width > 1:
        single = len(rows) == width and all(isinstance(v, (int, float)) or _is_scalar(v) for v in rows)
        if single:
            rows = [rows]
        flat = []
        for k, row in enumerate(rows):
            row = list(row)
            if len(row) != width:
                raise ValueError("%s: row %d has %d numbers, expected %d" % (what, k, len(row), width))
            flat.extend(float(v) for v in row)
    else:
        single = isinstance(values, (int, float))
        flat = [float(v) for v in rows]
    n = len(flat) // width
    buf = (ctypes.c_double * max(len(flat), 1))(*flat)
    return buf, n, single, False


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


class Model:
    """A robot model: a nominal robot file or a calibrated model, with the
    nominal table it corrects. Load with Model.load(path); a calibration's
    identified model is Result.model."""

    def __init__(self, handle):
        self._h = ctypes.c_void_p(handle)
        self._free = _lib.lib().rch_ffi_model_free

    @classmethod
    def load(cls, path):
        """Load a model file (rcal-model/1 JSON). Raises RcalError with the
        reader's "file:line:col: message" when it is missing or malformed."""
        lib = _lib.lib()
        h = ctypes.c_void_p()
        err = ctypes.create_string_buffer(_ERR_LEN)
        _check(lib.rch_ffi_model_load(ctypes.byref(h), _path(path), err, _ERR_LEN), err)
        return cls(h.value)

    def __del__(self):
        if getattr(self, "_h", None) and self._h.value:
            self._free(self._h)
            self._h = ctypes.c_void_p()

    @property
    def name(self):
        """The model's name (the file's "name")."""
        buf = ctypes.create_string_buffer(256)
        _lib.lib().rch_ffi_model_name(self._h, buf, 256)
        return buf.value.decode(errors="replace")

    @property
    def has_nominal(self):
        """True for a calibrated model that carries its nominal table."""
        return bool(_lib.lib().rch_ffi_model_has_nominal(self._h))

    @property
    def joint_limits_deg(self):
        """Joint limits: 6 pairs (min, max), degrees."""
        lo, hi = (ctypes.c_double * 6)(), (ctypes.c_double * 6)()
        _check(_lib.lib().rch_ffi_model_limits(self._h, lo, hi))
        return [(lo[j], hi[j]) for j in range(6)]

    def params(self, nominal=False):
        """The parameters as a list of (name, unit, value): lengths in mm,
        angles in degrees ("a1", "d1", "alpha1", "theta1", ..., "ex", "ey",
        "ez", then the effects'). nominal=True: the 27 base parameters of the
        nominal table (the encoder is the model's)."""
        lib = _lib.lib()
        n = lib.rch_ffi_model_n_params(self._h)
        out = []
        for k in range(27 if nominal else n):
            name = ctypes.create_string_buffer(64)
            v, u = ctypes.c_double(), ctypes.c_int()
            _check(lib.rch_ffi_model_param(self._h, k, 1 if nominal else 0, name, 64, ctypes.byref(v),
                                           ctypes.byref(u)))
            out.append((name.value.decode(), _UNITS[u.value], v.value))
        return out

    def fk(self, q_deg, nominal=False, rotation=False, determined=False):
        """Forward kinematics: the flange point (x, y, z) in mm, base frame, at
        joint angles q_deg (degrees). One pose (6 numbers) gives one (x, y, z);
        a batch (n x 6) gives n of them ((n, 3) numpy array for numpy input).
        nominal=True uses the nominal table of a calibrated model;
        determined=True the part of it compensation uses (the DH parameters
        the data did not determine held nominal).
        rotation=True also returns the flange rotation(s) as 9 numbers,
        row-major: ((x, y, z), R)."""
        lib = _lib.lib()
        q, n, single, numpy = _doubles(q_deg, 6, "q_deg")
        pos = (ctypes.c_double * max(3 * n, 1))()
        rot = (ctypes.c_double * max(9 * n, 1))() if rotation else None
        err = ctypes.create_string_buffer(_ERR_LEN)
        which = 1 if nominal else (2 if determined else 0)
        _check(lib.rch_ffi_fk(self._h, which, pos, rot, q, n, err, _ERR_LEN), err)
        p = _rows(pos, n, 3, single, numpy)
        return (p, _rows(rot, n, 9, single, numpy)) if rotation else p

    def cable_length(self, q_deg):
        """Predicted cable length in mm at joint angles q_deg (degrees): the
        distance from the encoder outlet to the flange (tool) point plus the
        model's length-side effects. One pose gives a float, a batch a list
        (numpy array for numpy input)."""
        lib = _lib.lib()
        q, n, single, numpy = _doubles(q_deg, 6, "q_deg")
        out = (ctypes.c_double * max(n, 1))()
        err = ctypes.create_string_buffer(_ERR_LEN)
        _check(lib.rch_ffi_cable_length(self._h, out, q, n, err, _ERR_LEN), err)
        return _rows(out, n, 1, single, numpy)


class Result:
    """The result of calibrate(): the same figures `rcal calibrate --json`
    prints.

    before, after:             Metrics on the held-out samples (the training
                               samples when none is held out), mm
    train_before, train_after: Metrics on the training samples, mm
    params:                    list of Param (value, delta in mm or deg)
    encoder_mm:                (ex, ey, ez) identified encoder outlet, mm
    n_train, n_test, converged, exit, iterations, cost_evals, method, seed
    truth_flange:              with truth=: flange errors against the truth
                               (before/after RMS and max, mm), else None
    json(), json_text():       the report as `rcal calibrate --json` prints it
    model:                     the identified Model (full precision)
    write(path):               the calibrated model file (`--out`), never
                               over one of the inputs
    """

    def __init__(self, handle, method, data, seed):
        lib = _lib.lib()
        self._h = ctypes.c_void_p(handle)
        self._free = lib.rch_ffi_calib_free
        self.method, self.data, self.seed = method, data, seed
        ms = []
        for which in range(4):
            out = (ctypes.c_double * 6)()
            _check(lib.rch_ffi_calib_metrics(self._h, which, out))
            ms.append(Metrics(int(out[0]), *out[1:6]))
        self.before, self.after, self.train_before, self.train_after = ms
        n_train, n_test = ctypes.c_size_t(), ctypes.c_size_t()
        conv, it, ev = ctypes.c_int(), ctypes.c_uint(), ctypes.c_uint()
        ex = ctypes.create_string_buffer(128)
        _check(lib.rch_ffi_calib_info(self._h, ctypes.byref(n_train), ctypes.byref(n_test), ctypes.byref(conv),
                                      ctypes.byref(it), ctypes.byref(ev), ex, 128))
        self.n_train, self.n_test = n_train.value, n_test.value
        self.converged, self.iterations, self.cost_evals = bool(conv.value), it.value, ev.value
        self.exit = ex.value.decode()
        self.params = []
        for k in range(lib.rch_ffi_calib_n_params(self._h)):
            name = ctypes.create_string_buffer(64)
            v, dv, u = ctypes.c_double(), ctypes.c_double(), ctypes.c_int()
            _check(lib.rch_ffi_calib_param(self._h, k, name, 64, ctypes.byref(v), ctypes.byref(dv),
                                           ctypes.byref(u)))
            self.params.append(Param(name.value.decode(), _UNITS[u.value], v.value, dv.value))
        self.encoder_mm = tuple(p.value for p in self.params[24:27])
        truth = (ctypes.c_double * 4)()
        self.truth_flange = None
        if lib.rch_ffi_calib_truth(self._h, truth) == 0:
            self.truth_flange = dict(zip(("before_rms_mm", "before_max_mm", "after_rms_mm", "after_max_mm"),
                                         truth[:4]))

    def json_text(self):
        """The report exactly as `rcal calibrate --json` prints it (the same
        writer; time_ms is this run's)."""
        lib = _lib.lib()
        needed = ctypes.c_size_t()
        lib.rch_ffi_calib_json(self._h, None, 0, ctypes.byref(needed))
        buf = ctypes.create_string_buffer(needed.value)
        _check(lib.rch_ffi_calib_json(self._h, buf, needed.value, None))
        return buf.value.decode()

    def json(self):
        """json_text() parsed: a dict."""
        import json
        return json.loads(self.json_text())

    def __del__(self):
        if getattr(self, "_h", None) and self._h.value:
            self._free(self._h)
            self._h = ctypes.c_void_p()

    @property
    def model(self):
        """The identified model with the robot's nominal table (a new Model)."""
        lib = _lib.lib()
        h = ctypes.c_void_p()
        err = ctypes.create_string_buffer(_ERR_LEN)
        _check(lib.rch_ffi_calib_model(ctypes.byref(h), self._h, err, _ERR_LEN), err)
        return Model(h.value)

    def param(self, name):
        """The Param called name ("a2", "theta3", "ex", ...)."""
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)

    def write(self, path):
        """Write the calibrated model file, as `rcal calibrate --out path`
        writes it (rcal-model/1 JSON, for `rcal compensate` and Model.load)."""
        err = ctypes.create_string_buffer(_ERR_LEN)
        _check(_lib.lib().rch_ffi_calib_write(self._h, _path(path), err, _ERR_LEN), err)

    def __repr__(self):
        return "<rcal.Result %s: %d train / %d test, RMSE %.4f -> %.4f mm>" % (
            self.method, self.n_train, self.n_test, self.before.rmse_mm, self.after.rmse_mm)


def calibrate(data_csv=None, q_deg=None, L_mm=None, robot=None, method="lm", test_fraction=0.1, seed=1,
              max_iter=0, fix=None, tool_offset=False, truth=None):
    """Identify the DH errors and the encoder outlet from cable lengths, as
    `rcal calibrate` does (the same host function: identical figures).

    data_csv:      measurements CSV (q1..q6 in degrees, L in mm), or
    q_deg, L_mm:   the samples as arrays: (n x 6) joint readings in degrees
                   and (n) cable lengths in mm, in acquisition order
    robot:         nominal robot model file (default: default_robot())
    method:        "lm" (default), "ltlm", "lm-paper" or "ltlm-paper"
    test_fraction: share of the samples held out for the before/after figures
    seed:          split (and LTLM) seed
    max_iter:      iteration cap, 0 for the method's default
    fix:           parameters held at nominal: "a1,theta6" or a list of names
    tool_offset:   also identify where the cable is attached on the flange
    truth:         a simulated truth model file: Result.truth_flange
    Returns a Result. Raises RcalError (bad file with file:line:col, too few
    samples, unknown method) or ValueError (bad arguments)."""
    if (data_csv is None) == (q_deg is None):
        raise ValueError("calibrate: give either data_csv or q_deg and L_mm")
    lib = _lib.lib()
    robot = default_robot() if robot is None else robot
    if fix is not None and not isinstance(fix, str):
        fix = ",".join(fix)
    h = ctypes.c_void_p()
    err = ctypes.create_string_buffer(_ERR_LEN)
    common = (method.encode(), float(test_fraction), int(seed), int(max_iter),
              None if fix is None else fix.encode(), 1 if tool_offset else 0, _opt_path(truth), err, _ERR_LEN)
    if data_csv is not None:
        st = lib.rch_ffi_calibrate_file(ctypes.byref(h), _path(data_csv), _path(robot), *common)
        data = os.fspath(data_csv)
    else:
        if L_mm is None:
            raise ValueError("calibrate: q_deg needs L_mm")
        q, n, _, _ = _doubles(q_deg, 6, "q_deg")
        L, nl, _, _ = _doubles(L_mm, 1, "L_mm")
        if n != nl:
            raise ValueError("calibrate: %d poses but %d lengths" % (n, nl))
        st = lib.rch_ffi_calibrate_arrays(ctypes.byref(h), q, L, n, _path(robot), *common)
        data = None
    _check(st, err)
    return Result(h.value, method, data, int(seed))


def compensate(model, targets_deg, nominal=None, position_only=None, max_dev_deg=0.0, return_status=False):
    """Correct joint targets made with the nominal model so that the
    calibrated robot reaches the nominal flange pose: q' with
    FK_cal(q') = FK_nom(q), target by target in order with one stream, as
    `rcal compensate` does line by line.

    model:         the calibrated Model (e.g. Model.load("cal.json"))
    targets_deg:   one target (6 joint angles, degrees) or a batch (n x 6)
    nominal:       the Model the targets were made with (default: the
                   calibrated model's nominal table)
    position_only: True position only, False position and orientation,
                   None (default) as the model file says, like `rcal
                   compensate` (position only unless the data determined
                   the orientation). The model used is the determined part
                   of the calibration (parameters the data did not
                   determine held nominal).
    max_dev_deg:   largest correction per joint, degrees (0: 0.1 rad)
    Returns the corrected targets in degrees, shaped like the input; with
    return_status=True also a list of per-target codes: 0 converged, 1
    position matched with the orientation best effort, 2 not converged
    (target plus the last good correction), 3 left uncompensated (the
    model's 95 % position uncertainty there is above 1 mm). A target outside the joint limits
    raises RcalError."""
    lib = _lib.lib()
    q, n, single, numpy = _doubles(targets_deg, 6, "targets_deg")
    out = (ctypes.c_double * max(6 * n, 1))()
    status = (ctypes.c_int * max(n, 1))()
    err = ctypes.create_string_buffer(_ERR_LEN)
    _check(lib.rch_ffi_compensate(model._h, nominal._h if nominal is not None else None, out, status, q, n,
                                  0 if position_only is None else (1 if position_only else 2),
                                  float(max_dev_deg), err, _ERR_LEN), err)
    corrected = _rows(out, n, 6, single, numpy)
    if return_status:
        codes = list(status[:n])
        return corrected, (codes[0] if single else codes)
    return corrected
