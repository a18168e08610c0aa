# SPDX-License-Identifier: MIT
"""rcal: robot calibration with a cable encoder, from Python.

A thin ctypes layer over the C libraries of this repository (the flat API of
tools/host/outputs/rch_ffi.h in librcal_ffi.so, shipped inside the package
by `pip install ./python`), so every figure is the one the command-line tool
prints: each function calls the host function the command calls
(calibrate: rch_calib_run, diagnose: rch_diagnose_file, evaluate:
rch_evaluate, compensate: the set-up of rch_comp_run and its stream,
export: rch_export_file, report: rch_report_write).

Units: joint angles in DEGREES, lengths in MILLIMETRES, everywhere.
Arrays: a pose is 6 numbers (q1..q6); a batch is n poses, as a list of lists
or an (n, 6) numpy array. Results come back as tuples and lists, or as numpy
arrays when the input was a numpy array (numpy is optional).

    import rcal
    r = rcal.calibrate("data/sim_irb120.csv")                 # rcal calibrate --data ...
    print(r.before.rmse_mm, r.after.rmse_mm, r.param("a2").std_error)
    r.write("cal.json")
    g = rcal.diagnose("data/sim_irb120.csv")                  # rcal diagnose --data ...
    print(g.effect, g.next_command)
    q_new = rcal.compensate("cal.json", [[10, 20, 30, 0, 40, 0]], tool_mm=(0, 0, 100))

Errors raise RcalError with the C library's message ("file:line:col: ...").
"""

from __future__ import annotations

import collections
import ctypes
import math
import os
import shutil
import tempfile
import warnings

from . import _lib
from ._check import _ints, _doubles, _real, _rows

from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

# The types of the public signatures (annotations only: nothing is checked at
# run time beyond what each function checks itself). ArrayLike: a list of
# numbers, a list of lists or a numpy array; PathLike: a str or os.PathLike.
PathLike = Union[str, "os.PathLike[str]"]
Paths = Union[PathLike, Sequence[PathLike]]
ArrayLike = Any
Triple = Sequence[float]

__all__ = ["RcalError", "RcalWarning", "Model", "Metrics", "Param", "Jump", "Result", "Diagnosis", "Evaluation", "Compensation",
           "calibrate", "diagnose", "evaluate", "compensate", "export", "report", "default_robot", "data_file",
           "library_path", "lapack"]

try:  # optional
    import numpy as _np
except ImportError:  # pragma: no cover - depends on the machine
    _np = None

_ERR_LEN = 2048


def __getattr__(name):
    """rcal.__version__: the C library's version (rc_version()), read when
    first asked (so that `import rcal` itself never fails)."""
    if name == "__version__":
        return _lib.lib().rch_ffi_version().decode()
    raise AttributeError("module 'rcal' has no attribute %r" % name)


def library_path() -> str:
    """Path of the librcal_ffi.so in use (RCAL_FFI_LIB, the package's own,
    or a build tree's)."""
    return _lib.lib().rcal_path


Metrics = collections.namedtuple("Metrics", "n rmse_mm mean_abs_mm sd_mm mean_mm max_mm")
Metrics.__doc__ = """Cable-length error over a sample set, mm (n: number of samples; mean_abs_mm is
what the paper's Eq. 20 calls SD, sd_mm the true standard deviation)."""

Param = collections.namedtuple("Param", "name unit value delta std_error identifiability data_vs_prior prior_sd "
                                        "compensation")
Param.__doc__ = """One identified parameter as `rcal calibrate --json` lists it: unit "mm", "deg"
or "-"; value and delta against nominal in that unit (the encoder's delta is
against the before-calibration fit); std_error in that unit (NaN: none);
identifiability "identifiable", "weak", "not identifiable" or "fixed";
data_vs_prior "determined", "partly", "prior only" (None: no prior on it);
prior_sd (0: none); compensation "fitted", "nominal" (held nominal by
compensation) or "not used" (encoder, effects). The uncertainty fields are
None when the run has no uncertainty."""

Jump = collections.namedtuple("Jump", "line size_mm se_mm")
Jump.__doc__ = """A length jump fitted in acquisition order: the data-file line of the first
sample after it (0 when several files were merged), its size and standard
error, mm."""

_UNITS = {0: "mm", 1: "deg", 2: "-"}


class RcalWarning(UserWarning):
    """What the CLI writes on stderr as a warning: a row left out of the fit
    (calibrate), a target not compensated or beyond the uncertainty limit
    (compensate)."""


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


def _opt_str(v):
    if v is None:
        return None
    if not isinstance(v, str):
        v = ",".join(v)
    return v.encode()


def _data_dir():
    d = os.environ.get("RCAL_DATA_DIR")
    if d:
        return d
    shipped = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data")
    if os.path.isdir(shipped):
        return shipped
    return os.path.join(_lib.repo_root(), "data")


def data_file(name: str) -> str:
    """Path of a data file shipped with rcal ("irb120.json", "kr6.json",
    "sim_irb120.csv", "sim_irb120_truth.json"): in $RCAL_DATA_DIR when set,
    else the package's own copy (an installed package), else the
    repository's data/."""
    return os.path.join(_data_dir(), name)


Lapack = collections.namedtuple("Lapack", "line linked_in version")
Lapack.__doc__ = """The BLAS/LAPACK the library computes with: line as `rcal --version` prints
it after "BLAS/LAPACK: ", linked_in True when LAPACK and BLAS are inside
librcal_ffi.so (the build's pinned reference archives: no other BLAS/LAPACK
on the machine or in the process changes a result), version LAPACK's
ILAVER as a string ("3.11.0")."""


def lapack() -> "Lapack":
    """Which BLAS/LAPACK librcal_ffi.so computes with (a Lapack)."""
    buf = ctypes.create_string_buffer(4096)
    linked = ctypes.c_int()
    ver = (ctypes.c_int * 3)()
    _check(_lib.lib().rch_ffi_lapack(buf, len(buf), ctypes.byref(linked), ver))
    return Lapack(buf.value.decode(), bool(linked.value), "%d.%d.%d" % tuple(ver))


def default_robot() -> str:
    """Path of the nominal robot model `rcal` uses by default: irb120.json
    by data_file()."""
    return data_file("irb120.json")


def _text(fn, h):
    needed = ctypes.c_size_t()
    fn(h, None, 0, ctypes.byref(needed))
    buf = ctypes.create_string_buffer(needed.value)
    _check(fn(h, buf, needed.value, None))
    return buf.value.decode()


class Model:
    """A robot model: a nominal robot file or a calibrated model, with the
    nominal table it corrects. Load with Model.load(path); a calibration's
    identified model is Result.model."""

    def __init__(self, handle, path=None):
        self._h = ctypes.c_void_p(handle)
        self._free = _lib.lib().rch_ffi_model_free
        self.path = None if path is None else os.fspath(path)  # the file it was loaded from, if any

    @classmethod
    def load(cls, path: PathLike) -> "Model":
        """Load a model file (rcal-model/1 JSON). Raises RcalError with the
        reader's "file:line:col: message" when it is missing or malformed."""
        lib = _lib.lib()
        h = ctypes.c_void_p()
        err = ctypes.create_string_buffer(_ERR_LEN)
        _check(lib.rch_ffi_model_load(ctypes.byref(h), _path(path), err, _ERR_LEN), err)
        return cls(h.value, path)

    def __del__(self):
        if getattr(self, "_h", None) and self._h.value:
            self._free(self._h)
            self._h = ctypes.c_void_p()

    @property
    def name(self) -> str:
        """The model's name (the file's "name")."""
        buf = ctypes.create_string_buffer(256)
        _lib.lib().rch_ffi_model_name(self._h, buf, 256)
        return buf.value.decode(errors="replace")

    @property
    def has_nominal(self) -> bool:
        """True for a calibrated model that carries its nominal table."""
        return bool(_lib.lib().rch_ffi_model_has_nominal(self._h))

    @property
    def joint_limits_deg(self) -> List[Tuple[float, float]]:
        """Joint limits: 6 pairs (min, max), degrees."""
        lo, hi = (ctypes.c_double * 6)(), (ctypes.c_double * 6)()
        _check(_lib.lib().rch_ffi_model_limits(self._h, lo, hi))
        return [(lo[j], hi[j]) for j in range(6)]

    def params(self, nominal: bool = False) -> List[Tuple[str, str, float]]:
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

    def fk(self, q_deg: ArrayLike, nominal: bool = False, rotation: bool = False, determined: bool = False) -> Any:
        """Forward kinematics: the flange point (x, y, z) in mm, base frame, at
        joint angles q_deg (degrees); the cable's attachment point where the
        model has a tool_offset (a one-point cable calibration's, in the
        flange frame: the flange is pos - R t). One pose (6 numbers) gives one (x, y, z);
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

    def cable_length(self, q_deg: ArrayLike) -> Any:
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
    after_unambiguous:         with jumps: held-out Metrics without the samples
                               between a jump and its training rows, else None
    validation:                Metrics on the validate= file (no refit), else None
    params:                    list of Param (value, delta, std_error, classes)
    encoder_mm:                (ex, ey, ez) identified encoder outlet, mm
    predicted:                 the predicted 95 % uncertainty (dict: position
                               over the data and the workspace, mm; orientation,
                               deg; orientation_determined), None without one
    jumps:                     list of Jump fitted (empty without)
    outlets:                   the data's encoder-place labels (place 0 is e)
    n_data, n_train, n_test, converged, exit, iterations, cost_evals, method, seed
    truth_flange:              with truth=: flange errors against the truth
                               (before/after RMS and max, mm), else None
    figure(name):              any figure of rch_ffi_calib_get ("noise_mm", ...)
    json(), json_text():       the report as `rcal calibrate --json` prints it
    model:                     the identified Model (full precision)
    write(path):               the calibrated model file (`--out`), never
                               over one of the inputs
    report(directory, ...):    the HTML report into a directory
    """

    def __init__(self, handle, method, data, seed):
        lib = _lib.lib()
        self._h = ctypes.c_void_p(handle)
        self._free = lib.rch_ffi_calib_free
        self.method, self.data, self.seed = method, data, seed
        ms = []
        for which in range(6):
            out = (ctypes.c_double * 6)()
            if lib.rch_ffi_calib_metrics(self._h, which, out) != 0:
                ms.append(None)
            else:
                ms.append(Metrics(int(out[0]), *out[1:6]))
        self.before, self.after, self.train_before, self.train_after, self.after_unambiguous, self.validation = ms
        n_train, n_test = ctypes.c_size_t(), ctypes.c_size_t()
        conv, it, ev = ctypes.c_int(), ctypes.c_uint(), ctypes.c_uint()
        ex = ctypes.create_string_buffer(128)
        _check(lib.rch_ffi_calib_info(self._h, ctypes.byref(n_train), ctypes.byref(n_test), ctypes.byref(conv),
                                      ctypes.byref(it), ctypes.byref(ev), ex, 128))
        self.n_train, self.n_test = n_train.value, n_test.value
        self.converged, self.iterations, self.cost_evals = bool(conv.value), it.value, ev.value
        self.exit = ex.value.decode()
        self.n_data = int(self.figure("n_data"))
        self.params = []
        for k in range(lib.rch_ffi_calib_n_params(self._h)):
            name = ctypes.create_string_buffer(64)
            v, dv, u = ctypes.c_double(), ctypes.c_double(), ctypes.c_int()
            _check(lib.rch_ffi_calib_param(self._h, k, name, 64, ctypes.byref(v), ctypes.byref(dv),
                                           ctypes.byref(u)))
            se, psd, held = ctypes.c_double(), ctypes.c_double(), ctypes.c_int()
            cls, pcls = ctypes.create_string_buffer(32), ctypes.create_string_buffer(32)
            unc = None
            if lib.rch_ffi_calib_param_unc(self._h, k, ctypes.byref(se), ctypes.byref(psd), cls, 32, pcls, 32,
                                           ctypes.byref(held)) == 0:
                unc = (se.value, cls.value.decode(), pcls.value.decode() or None, psd.value,
                       ("nominal" if held.value else "fitted") if k < 24 else "not used")
            self.params.append(Param(name.value.decode(), _UNITS[u.value], v.value, dv.value,
                                     *(unc if unc else (None,) * 5)))
        self.encoder_mm = tuple(p.value for p in self.params[24:27])
        truth = (ctypes.c_double * 4)()
        self.truth_flange = None
        if lib.rch_ffi_calib_truth(self._h, truth) == 0:
            self.truth_flange = dict(zip(("before_rms_mm", "before_max_mm", "after_rms_mm", "after_max_mm"),
                                         truth[:4]))
        self.predicted = None
        if self.figure("position95_data_median_mm") is not None:
            keys = ("position95_data_median_mm", "position95_data_max_mm", "position95_workspace_median_mm",
                    "position95_workspace_max_mm", "orientation95_data_median_deg", "orientation95_data_max_deg")
            self.predicted = {k: self.figure(k) for k in keys}
            self.predicted["orientation_determined"] = bool(self.figure("orientation_determined"))
        n = ctypes.c_uint()
        _check(lib.rch_ffi_calib_jumps(self._h, ctypes.byref(n), None, None, None, 0))
        line, size, sej = (ctypes.c_uint * max(n.value, 1))(), (ctypes.c_double * max(n.value, 1))(), \
            (ctypes.c_double * max(n.value, 1))()
        _check(lib.rch_ffi_calib_jumps(self._h, ctypes.byref(n), line, size, sej, n.value))
        self.jumps = [Jump(line[k], size[k], sej[k]) for k in range(n.value)]
        labels = (ctypes.c_int * 64)()
        _check(lib.rch_ffi_calib_outlets(self._h, ctypes.byref(n), labels, 64))
        self.outlets = list(labels[:min(n.value, 64)])

    @property
    def screened(self) -> List[Dict[str, Any]]:
        """The rows left out of the fit as irreconcilable with the rest (the
        JSON's "screened" "rows_left_out": dicts with file, line, sensor,
        residual_mm, likely, fits_outlet), [] when none."""
        sc = self.json().get("screened") or {}
        return list(sc.get("rows_left_out") or [])

    def figure(self, name: str) -> Optional[float]:
        """A figure of the run by name (rch_ffi_calib_get in rch_ffi.h:
        "noise_mm", "effective_params", "prior", "groups", "jumps_fitted",
        "dequant_corrected", "validate_ad_mean_mm", ...), or None when
        this run has none."""
        v = ctypes.c_double()
        if _lib.lib().rch_ffi_calib_get(self._h, name.encode(), ctypes.byref(v)) != 0:
            return None
        return v.value

    def json_text(self) -> str:
        """The report exactly as `rcal calibrate --json` prints it (the same
        writer; time_ms is this run's)."""
        return _text(_lib.lib().rch_ffi_calib_json, self._h)

    def json(self) -> Dict[str, Any]:
        """json_text() parsed: a dict."""
        import json
        return json.loads(self.json_text())

    def __del__(self):
        if getattr(self, "_h", None) and self._h.value:
            self._free(self._h)
            self._h = ctypes.c_void_p()

    @property
    def model(self) -> "Model":
        """The identified model with the robot's nominal table (a new Model)."""
        lib = _lib.lib()
        h = ctypes.c_void_p()
        err = ctypes.create_string_buffer(_ERR_LEN)
        _check(lib.rch_ffi_calib_model(ctypes.byref(h), self._h, err, _ERR_LEN), err)
        return Model(h.value)

    def param(self, name: str) -> "Param":
        """The Param called name ("a2", "theta3", "ex", ...)."""
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)

    def write(self, path: PathLike) -> None:
        """Write the calibrated model file, as `rcal calibrate --out path`
        writes it (rcal-model/2 JSON, for `rcal compensate` and Model.load)."""
        err = ctypes.create_string_buffer(_ERR_LEN)
        _check(_lib.lib().rch_ffi_calib_write(self._h, _path(path), err, _ERR_LEN), err)

    def report(self, directory: PathLike, diagnosis: Optional["Diagnosis"] = None, name: str = "report",
               model: Optional[PathLike] = None, tolerance_mm: Optional[float] = None) -> List[str]:
        """The HTML report: see rcal.report()."""
        return report(self, directory, diagnosis=diagnosis, name=name, model=model, tolerance_mm=tolerance_mm)

    def __repr__(self):
        return "<rcal.Result %s: %d train / %d test, RMSE %.4f -> %.4f mm>" % (
            self.method, self.n_train, self.n_test, self.before.rmse_mm, self.after.rmse_mm)


_CAL_FLAGS = {"tool_offset": 1, "jumps": 2, "dequantize": 4, "no_prior": 8, "holdout_groups": 16,
              "no_jump_check": 32, "no_screen": 64, "no_dequantize": 128, "prior_stated": 256,
              "no_length_offset": 512, "no_drift": 1024, "force": 2048}


def calibrate(data: Optional[Paths] = None, q_deg: ArrayLike = None, L_mm: ArrayLike = None,
              xyz_mm: ArrayLike = None, group: ArrayLike = None, outlet: ArrayLike = None,
              robot: Optional[PathLike] = None, method: str = "lm", test_fraction: float = 0.1, seed: int = 1,
              max_iter: int = 0, fix: Optional[Union[str, Sequence[str]]] = None,
              effects: Optional[Union[str, Sequence[str]]] = None, jumps: bool = False,
              dequantize: Optional[bool] = None, prior: bool = True, prior_stated: bool = False,
              tool_offset: bool = False, holdout_groups: bool = False, jump_check: bool = True,
              validate: Optional[PathLike] = None, truth: Optional[PathLike] = None, cases: int = 1,
              samples: int = 0, plots: Optional[PathLike] = None, residuals: Optional[PathLike] = None,
              data_csv: Optional[Paths] = None, positions: Optional[Paths] = None, screen: bool = True,
              target: ArrayLike = None, cable_points: Optional[Sequence[Triple]] = None,
              cable_point_sd: Optional[float] = None, length_offset: bool = True, drift: bool = True,
              force: bool = False) -> "Result":
    """Identify the DH errors and the encoder outlet from cable lengths, as
    `rcal calibrate` does (the same host function: identical figures).
    Each argument is the CLI option of the same meaning.

    data:           measurements CSV (q1..q6 deg, L mm; optional x, y, z, t,
                    group, outlet columns), or a list of them (several --data,
                    merged); data_csv= is the same
    q_deg, L_mm:    or the samples as arrays: (n x 6) joint readings in degrees
                    and (n) cable lengths in mm, in acquisition order, with
                    optional xyz_mm (n x 3, for dequantize), group (n) and
                    outlet (n) labels
    robot:          nominal robot model file (--robot; default: default_robot())
    method:         "lm" (default), "ltlm", "lm-paper", "ltlm-paper",
                    "lm-paper-deg", "ltlm-paper-deg"
    test_fraction:  share of the samples held out (--test-fraction)
    seed:           split (and LTLM) seed; max_iter: iteration cap (0: default)
    fix:            parameters held at nominal: "a1,theta6" or a list of names
    effects:        effects fitted with the geometry (--effects): "cable_sag,
                    joint_periodic:2" or a list, e.g. Diagnosis.effects
    jumps:          fit length jumps (--jumps); dequantize: None (default) recovers
                    rounded joints from x, y, z when the file shows rounding,
                    True forces it (--dequantize-joints), False keeps the
                    joints as read (--no-dequantize-joints)
    prior:          False for --no-prior (plain least squares); prior_stated:
                    True for --prior-stated (no scale from the data)
    tool_offset:    --tool-offset; holdout_groups: --holdout-groups;
    jump_check:     False for --no-jump-check
    validate:       a file the fit never sees (--validate): Result.validation
    truth:          a simulated truth model file: Result.truth_flange
    cases, samples: --cases, --samples (the paper's protocol)
    plots, residuals: --plots DIR, --residuals FILE.csv
    positions:      laser-tracker positions CSV(s) (--positions: one path or
                    a list), alone or with data; the same plausibility checks
                    (units, handedness, targets, pose ids, duplicates, the
                    controller's own x, y, z) as the CLI
    screen:         False for --no-screen (every row fitted); by default rows
                    irreconcilable with the rest are left out and listed in
                    Result.screened (a RcalWarning names each, as the CLI's
                    stderr does), a file with too many refused
    cable_points:   the nominal points of a tool plate the cable is hooked on in
                    turn, flange frame, mm: a list of (x, y, z), in the order of
                    the data's target column (--cable-point, once per point);
                    cable_point_sd: their tolerance in mm (--cable-point-sd)
    target:         with q_deg: (n) the plate point (0, 1, ...) each length
                    was measured on (a file's target column)
    length_offset, drift: False for --no-length-offset, --no-drift (by default
                    each is weighed by its evidence and fitted when it wins:
                    Result.figure("length_offset_fitted"), "drift_fitted")
    force:          --force: Result.write writes a model the judge refuses
                    (its noise beyond 10 x what the sensor can produce, or
                    worse than the nominal model: Result.figure("judge_usable"),
                    Result.json()["estimation"]["judge"])
    Returns a Result. Raises RcalError (bad file with file:line:col, too few
    samples, unknown method or effect) or ValueError (bad arguments)."""
    if data is None:
        data = data_csv
    elif data_csv is not None:
        raise ValueError("calibrate: give data or data_csv, not both")
    pbytes, plist = _path_list(positions, "positions")
    if q_deg is not None and (data is not None or plist):
        raise ValueError("calibrate: give either files (data and/or positions) or q_deg and L_mm")
    if data is None and q_deg is None and not plist:
        raise ValueError("calibrate: give either data (a file or a list of files), positions, or q_deg and L_mm")
    if q_deg is None and (L_mm is not None or xyz_mm is not None or group is not None or outlet is not None or
                          target is not None):
        raise ValueError("calibrate: L_mm, xyz_mm, group, outlet and target go with q_deg (arrays), not with files")
    pts, npts = None, 0
    if cable_points is not None:
        pts, npts, _, _ = _doubles(cable_points, 3, "cable_points")
    if cable_point_sd is not None and not (_real(cable_point_sd) and 1e-6 <= float(cable_point_sd) <= 100.0):
        raise ValueError("calibrate: cable_point_sd must be a number of mm in [1e-06, 100]")
    pts_sd = 0.0 if cable_point_sd is None else float(cable_point_sd)
    if not isinstance(method, str):
        raise ValueError("calibrate: method must be a string")
    lib = _lib.lib()
    robot = default_robot() if robot is None else robot
    flags = 0
    if dequantize not in (None, True, False):
        raise ValueError("calibrate: dequantize must be None (automatic), True or False")
    for name, on in (("tool_offset", tool_offset), ("jumps", jumps), ("dequantize", dequantize is True),
                     ("no_dequantize", dequantize is False), ("prior_stated", prior_stated),
                     ("no_prior", not prior), ("holdout_groups", holdout_groups), ("no_jump_check", not jump_check),
                     ("no_screen", not screen), ("no_length_offset", not length_offset), ("no_drift", not drift),
                     ("force", force)):
        if on:
            flags |= _CAL_FLAGS[name]
    h = ctypes.c_void_p()
    err = ctypes.create_string_buffer(_ERR_LEN)
    common = (_path(robot), method.encode(), float(test_fraction), int(seed), int(max_iter), _opt_str(fix),
              _opt_str(effects), flags, _opt_path(validate), _opt_path(truth), int(cases), int(samples),
              _opt_path(plots), _opt_path(residuals), err, _ERR_LEN)
    if data is not None or plist:
        _, files = _path_list(data, "data") if data is not None else (b"", [])
        if data is not None and not files:
            raise ValueError("calibrate: no data file")
        arr = (ctypes.c_char_p * max(len(files), 1))(*[_path(f) for f in files])
        parr = (ctypes.c_char_p * max(len(plist), 1))(*[_path(f) for f in plist])
        st = lib.rch_ffi_calibrate_inputs(ctypes.byref(h), arr, len(files), parr, len(plist), pts, npts, pts_sd,
                                          *common)
        every = files + plist
        label = every[0] if len(every) == 1 else every
    else:
        if L_mm is None:
            raise ValueError("calibrate: q_deg needs L_mm")
        q, n, _, _ = _doubles(q_deg, 6, "q_deg")
        L, nl, _, _ = _doubles(L_mm, 1, "L_mm")
        if n != nl:
            raise ValueError("calibrate: %d poses but %d lengths (L_mm: expected shape (%d,))" % (n, nl, n))
        xyz = None
        if xyz_mm is not None:
            xyz, nx, _, _ = _doubles(xyz_mm, 3, "xyz_mm")
            if nx != n:
                raise ValueError("calibrate: %d poses but %d xyz rows (xyz_mm: expected shape (%d, 3))" % (n, nx, n))
        st = lib.rch_ffi_calibrate_arrays(ctypes.byref(h), q, L, xyz, _ints(group, n, "group", 65535),
                                          _ints(outlet, n, "outlet", 255), _ints(target, n, "target", 15), n, pts,
                                          npts, pts_sd, *common)
        label = None
    _check(st, err)
    r = Result(h.value, method, label, int(seed))
    for w in r.screened:
        warnings.warn("rcal.calibrate: %s:%s: left out of the fit: %s residual %.4g mm, likely %s"
                      % (w.get("file"), w.get("line"), w.get("sensor"), w.get("residual_mm") or float("nan"),
                         w.get("likely")), RcalWarning, stacklevel=2)
    return r


Chosen = collections.namedtuple("Chosen", "name rmse_cv_mm gain_mm2 p_value")
DiagParam = collections.namedtuple("DiagParam", "name value se unit")


class Diagnosis:
    """The result of diagnose(): what `rcal diagnose` reports.

    effect:          the verdict ("length_jump", "cable_sag", "joint_periodic",
                     ..., "none", "unexplained"); joint: its joint (0: none)
    remaining, remaining_why: what is left after the chosen effects
    chosen:          list of Chosen(name, rmse_cv_mm, gain_mm2, p_value), the
                     effects added one after the other
    effects:         the --effects list the Next command passes (names as
                     calibrate(effects=...) takes them), jumps, dequantize;
                     the nuisance named is in it (time_drift) or in jumps
                     (length jumps; per set-up offsets, which calibrate fits
                     as the jumps at the set-up changes)
    nuisance:        the nuisance named (length_jump, time_drift,
                     group_offset): fitted by the Next command, never used
                     at a new pose
    params:          list of DiagParam(name, value, se, unit) fitted
    next_command:    the command that acts on the verdict (`Next:` of the CLI)
    noise_floor_mm, rmse_before_mm, rmse_after_mm, noise_est_mm, n, n_groups,
    n_jumps, ...:    figure(name) for any figure of rch_ffi_diag_get
    residuals():     (before, after, floor) per sample, mm (numpy when present)
    json(), write(path): `rcal diagnose --json`, `--out path`
    """

    _FIGURES = ("n", "n_groups", "folds", "noise_floor_mm", "floor_joints_mm", "floor_len_mm", "train_rmse_geo_mm",
                "rmse_before_mm", "rmse_after_mm", "noise_est_mm", "n_jumps", "rmse_jumps_mm", "jumps_implausible",
                "jump_max_mm", "dequant_corrected",
                "dequant_refused", "effect_rms_mm", "q_step_deg", "len_step_mm", "time_ms")

    def __init__(self, handle, data, robot_given=False):
        lib = _lib.lib()
        self._h = ctypes.c_void_p(handle)
        self._free = lib.rch_ffi_diag_free
        self.data = data
        eff, rem, why = (ctypes.create_string_buffer(64), ctypes.create_string_buffer(64),
                         ctypes.create_string_buffer(512))
        joint = ctypes.c_uint()
        _check(lib.rch_ffi_diag_verdict(self._h, eff, 64, ctypes.byref(joint), rem, 64, why, 512))
        self.effect, self.joint = eff.value.decode(), joint.value
        self.remaining, self.remaining_why = rem.value.decode(), why.value.decode()
        for k in self._FIGURES:
            v = self.figure(k)
            setattr(self, k, int(v) if k in ("n", "n_groups", "folds", "n_jumps", "jumps_implausible", "dequant_corrected",
                                             "dequant_refused") else v)
        self.chosen = []
        for k in range(int(self.figure("n_chosen"))):
            name = ctypes.create_string_buffer(64)
            a, b, c = ctypes.c_double(), ctypes.c_double(), ctypes.c_double()
            _check(lib.rch_ffi_diag_chosen(self._h, k, name, 64, ctypes.byref(a), ctypes.byref(b), ctypes.byref(c)))
            self.chosen.append(Chosen(name.value.decode(), a.value, b.value, c.value))
        self.params = []
        for k in range(int(self.figure("n_params"))):
            name, unit = ctypes.create_string_buffer(64), ctypes.create_string_buffer(16)
            v, se = ctypes.c_double(), ctypes.c_double()
            _check(lib.rch_ffi_diag_param(self._h, k, name, 64, ctypes.byref(v), ctypes.byref(se), unit, 16))
            self.params.append(DiagParam(name.value.decode(), v.value, se.value, unit.value.decode()))
        buf = ctypes.create_string_buffer(4096)
        self.next_command = (buf.value.decode() if lib.rch_ffi_diag_next(self._h, 1 if robot_given else 0, buf, 4096)
                             == 0 else None)
        args = self.next_command.split() if self.next_command else []
        self.jumps = "--jumps" in args
        self.dequantize = "--dequantize-joints" in args
        self.effects = args[args.index("--effects") + 1].split(",") if "--effects" in args else []
        nb = ctypes.create_string_buffer(256)
        _check(lib.rch_ffi_diag_nuisance(self._h, nb, 256))
        self.nuisance = [x for x in nb.value.decode().split(",") if x]

    def figure(self, name: str) -> Optional[float]:
        """A figure by name (rch_ffi_diag_get), or None when unknown."""
        v = ctypes.c_double()
        if _lib.lib().rch_ffi_diag_get(self._h, name.encode(), ctypes.byref(v)) != 0:
            return None
        return v.value

    def residuals(self) -> Any:
        """(before, after, floor): per sample as the diagnosis used them, the
        cross-validated held-out residual of the geometry, of the final model,
        and the noise-floor sigma, mm (numpy arrays when numpy is present)."""
        n = self.n
        bufs = [(ctypes.c_double * max(n, 1))() for _ in range(3)]
        _check(_lib.lib().rch_ffi_diag_residuals(self._h, *bufs))
        return tuple(_rows(b, n, 1, False, _np is not None) for b in bufs)

    def json_text(self) -> str:
        """The report exactly as `rcal diagnose --json` prints it."""
        return _text(_lib.lib().rch_ffi_diag_json, self._h)

    def json(self) -> Dict[str, Any]:
        import json
        return json.loads(self.json_text())

    def write(self, path: PathLike) -> None:
        """The calibrated model with the effects found, what `rcal diagnose
        --out path` writes (never over the data or the robot file)."""
        err = ctypes.create_string_buffer(_ERR_LEN)
        _check(_lib.lib().rch_ffi_diag_write(self._h, _path(path), err, _ERR_LEN), err)

    def __del__(self):
        if getattr(self, "_h", None) and self._h.value:
            self._free(self._h)
            self._h = ctypes.c_void_p()

    def __repr__(self):
        return "<rcal.Diagnosis %s: held-out %.4f -> %.4f mm, floor %.4f mm>" % (
            self.effect, self.rmse_before_mm, self.rmse_after_mm, self.noise_floor_mm)


def _path_list(v, what):
    """One path or a list of paths as the "\\n"-separated bytes the C API takes (b"" for None)."""
    if v is None:
        return b"", []
    paths = [os.fspath(p) for p in ([v] if isinstance(v, (str, bytes, os.PathLike)) else list(v))]
    if not all(isinstance(p, str) for p in paths) or any("\n" in p or not p for p in paths):
        raise ValueError(f"{what}: a path or a list of paths, none empty or with a newline")
    return "\n".join(paths).encode(), paths


def diagnose(data: Optional[Paths] = None, robot: Optional[PathLike] = None, seed: int = 1, folds: int = 5,
             steps: int = 3, jumps: bool = True, dequantize: bool = False, q_step_deg: float = 0.0,
             len_step_mm: float = 0.0, len_noise_mm: float = 0.0, alpha: float = 0.0, max_iter: int = 0,
             positions: Optional[Paths] = None, effects: Optional[Union[str, Sequence[str]]] = None,
             known_jumps: bool = False) -> "Diagnosis":
    """Which missing physical effect explains the residuals, as `rcal
    diagnose` finds it (rch_diagnose_inputs): data (--data: one path or a
    list, one or several outlets), positions (--positions: tracker files,
    one path or a list), both mixed, --robot, effects (--effects: those
    already known), --seed, --folds, --steps, jumps=False for --no-jumps,
    known_jumps=True for --jumps, --dequantize-joints, --q-step-deg,
    --len-step-mm (0: detected, < 0: none), --len-noise-mm, --alpha (0:
    0.01), --max-iter (0: 100). Returns a Diagnosis."""
    lib = _lib.lib()
    robot_given = robot is not None
    robot = default_robot() if robot is None else robot
    dbytes, dlist = _path_list(data, "data")
    pbytes, plist = _path_list(positions, "positions")
    if not dlist and not plist:
        raise ValueError("diagnose: give data (cable lengths) or positions (tracker), or both")
    h = ctypes.c_void_p()
    err = ctypes.create_string_buffer(_ERR_LEN)
    flags = (0 if jumps else 1) | (2 if dequantize else 0) | (4 if known_jumps else 0)
    if len(dlist) == 1 and not plist and effects is None and not known_jumps:  # the one-file call of before
        _check(lib.rch_ffi_diagnose(ctypes.byref(h), _path(dlist[0]), _path(robot), int(seed), int(folds), int(steps),
                                    flags, float(q_step_deg), float(len_step_mm), float(len_noise_mm), float(alpha),
                                    int(max_iter), err, _ERR_LEN), err)
    else:
        _check(lib.rch_ffi_diagnose_inputs(ctypes.byref(h), dbytes, pbytes, _path(robot), _opt_str(effects),
                                           int(seed), int(folds), int(steps), flags, float(q_step_deg),
                                           float(len_step_mm), float(len_noise_mm), float(alpha), int(max_iter), err,
                                           _ERR_LEN), err)
    return Diagnosis(h.value, dlist[0] if dlist else plist[0], robot_given)


Evaluation = collections.namedtuple("Evaluation", "metrics encoder_refitted encoder_mm encoder_shift_mm poses "
                                                  "repeated_poses ad_mean_mm ad_max_mm rd_mean_mm rd_max_mm")
Evaluation.__doc__ = """A model on new data (`rcal evaluate --json`): metrics (Metrics of the
residuals, mm), the encoder outlet used (refitted alone when asked) and its
shift, the ISO 9283 distance accuracy AD and repeatability RD over the
repeated poses (NaN without repeated poses)."""


def _model(model, what="model"):
    """A Model from a Model, a Result of calibrate() (its model file, as
    Result.write writes it for `rcal calibrate --out`, read back: the
    posterior included) or a model file path; what names the argument in
    the error for anything else."""
    if isinstance(model, Model):
        return model
    if isinstance(model, Result):
        tmp = tempfile.mkdtemp(prefix="rcal-model-")
        try:
            path = os.path.join(tmp, "model.json")
            model.write(path)
            m = Model.load(path)
            m.path = None  # the temporary file is gone
            return m
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
    if isinstance(model, (str, bytes, os.PathLike)):
        return Model.load(model)
    raise TypeError("%s: expected an rcal.Model, an rcal.Result (from rcal.calibrate) or the path of a model file, "
                    "not %s" % (what, type(model).__name__))


def evaluate(model: Union["Model", "Result", PathLike], data: PathLike, refit_encoder: bool = False,
             same_pose_deg: float = 1e-6) -> "Evaluation":
    """A calibrated model (a Model, a Result of calibrate() or a model file)
    on data the fit never saw, as `rcal evaluate --model M --data D`
    (rch_evaluate: no refit of the robot; refit_encoder: --refit-encoder;
    same_pose_deg: --same-pose-deg). Returns an Evaluation."""
    m = _model(model, "evaluate: model")
    out = (ctypes.c_double * 17)()
    err = ctypes.create_string_buffer(_ERR_LEN)
    _check(_lib.lib().rch_ffi_evaluate(out, m._h, _path(data), 1 if refit_encoder else 0, float(same_pose_deg), err,
                                       _ERR_LEN), err)
    v = list(out)
    return Evaluation(Metrics(int(v[0]), *v[1:6]), bool(v[6]), tuple(v[7:10]), v[10], int(v[11]), int(v[12]),
                      *v[13:17])


Compensation = collections.namedtuple("Compensation", "q_deg status u95_mm orientation")
Compensation.__doc__ = """compensate(..., details=True): the corrected targets (deg, shaped like the
input), a status per target (0 converged, 1 position matched with the
orientation best effort, 2 not converged: the closest point found (on a path:
the target plus the last good correction), 3 left uncompensated: uncertainty above the limit), u95_mm,
the predicted 95 % position uncertainty of the compensated point per target
(what --uncertainty-out writes; NaN when the model has no uncertainty: unknown,
never 0), and orientation, what `rcal compensate --summary` says of the
orientation: a dict with "corrected" (bool), "chosen_by" ("option",
"uncertainty" or "model_file"), "uncorrected_rms_deg" (the calibrated-vs-nominal
tilt of the tool's axis, the flange z axis, RMS over the joint limits) and
"correction_error_rms_deg" (the correction's predicted error of that tilt;
both NaN when the model has no covariance). The first three unpack as
before: q, status, u95 = c[:3]."""


_U95_POLICIES = {"skip": 0, "warn": 1, "refuse": 2}
_ON_FAIL = ("warn", "raise", "ignore")


def compensate(model: Union["Model", "Result", PathLike], targets_deg: ArrayLike,
               nominal: Optional[Union["Model", PathLike]] = None, tool_mm: Optional[Triple] = None,
               position_only: Optional[bool] = None, max_dev_deg: float = 0.0, max_uncertainty_mm: float = 0.0,
               return_status: bool = False, details: bool = False, u95_policy: str = "skip",
               on_fail: str = "warn") -> Any:
    """Correct joint targets made with the nominal model so that the
    calibrated robot reaches the nominal pose: q' with FK_cal(q') =
    FK_nom(q) for the tool point, target by target in order with one
    stream, with the model set-up of `rcal compensate` (its determined part,
    the cable attachment removed).

    model:         the calibrated Model, the Result of calibrate() (its
                   model file, as Result.write writes it) or a model file
                   (--model)
    targets_deg:   one target (6 joint angles, degrees) or a batch (n x 6)
    nominal:       the Model or file the targets were made with (--nominal;
                   default: the calibrated model's nominal table)
    tool_mm:       the TCP in the flange frame, mm (--tool X,Y,Z; default the
                   flange centre)
    position_only: True --position-only, False --full-pose, None (default)
                   as rcal compensate chooses: the orientation is corrected
                   when the calibrated-vs-nominal tilt of the tool's axis
                   exceeds the correction's predicted error (details=True
                   returns the figures)
    max_dev_deg:   largest correction per joint (--max-dev-deg; 0: 0.1 rad)
    max_uncertainty_mm: --max-uncertainty-mm (0: none for a model with a
                   posterior, 1 mm for one without)
    u95_policy:    --u95-policy: "skip" (default: a target beyond the limit
                   is left uncompensated, status 3), "warn" (compensated
                   anyway, a RcalWarning), "refuse" (RcalError, nothing
                   returned)
    on_fail:       a target not compensated (status 2 or 3): "warn" (default,
                   a RcalWarning naming it, as the CLI's stderr), "raise"
                   (RcalError naming the first), "ignore"
    Returns the corrected targets in degrees, shaped like the input (numpy in,
    numpy out); return_status=True: (targets, status codes); details=True: a
    Compensation (targets, status, u95_mm). A target outside the joint
    limits raises RcalError; a wrong shape or a non-finite value
    ValueError."""
    if u95_policy not in _U95_POLICIES:
        raise ValueError("compensate: u95_policy must be 'skip', 'warn' or 'refuse', not %r" % (u95_policy,))
    if on_fail not in _ON_FAIL:
        raise ValueError("compensate: on_fail must be 'warn', 'raise' or 'ignore', not %r" % (on_fail,))
    if position_only not in (None, True, False):
        raise ValueError("compensate: position_only must be None, True or False")
    for name, v in (("max_dev_deg", max_dev_deg), ("max_uncertainty_mm", max_uncertainty_mm)):
        if not _real(v) or not math.isfinite(float(v)) or float(v) < 0:
            raise ValueError("compensate: %s must be a finite number >= 0, not %r" % (name, v))
    lib = _lib.lib()
    cal = _model(model, "compensate: model")
    nom = None if nominal is None else _model(nominal, "compensate: nominal")
    q, n, single, numpy = _doubles(targets_deg, 6, "targets_deg")
    out = (ctypes.c_double * max(6 * n, 1))()
    status = (ctypes.c_int * max(n, 1))()
    u95 = (ctypes.c_double * max(n, 1))()
    tool = None
    if tool_mm is not None:
        tb, nt, _, _ = _doubles(tool_mm, 3, "tool_mm")
        if nt != 1:
            raise ValueError("tool_mm: expected shape (3,) (x, y, z in the flange frame, mm)")
        tool = tb
    err = ctypes.create_string_buffer(_ERR_LEN)
    _check(lib.rch_ffi_compensate(cal._h, nom._h if nom is not None else None, out, status, u95, q, n,
                                  0 if position_only is None else (1 if position_only else 2),
                                  float(max_dev_deg), float(max_uncertainty_mm), _U95_POLICIES[u95_policy], tool, err,
                                  _ERR_LEN), err)
    corrected = _rows(out, n, 6, single, numpy)
    codes = list(status[:n])
    _flag_targets(codes, list(u95[:n]), max_uncertainty_mm, u95_policy, on_fail)
    if details:
        u = _rows(u95, n, 1, single, numpy)
        mode = (ctypes.c_double * 4)()
        _check(lib.rch_ffi_compensate_mode(cal._h, nom._h if nom is not None else None,
                                           0 if position_only is None else (1 if position_only else 2),
                                           float(max_dev_deg), tool, mode, err, _ERR_LEN), err)
        orient = {"corrected": mode[0] == 0.0, "chosen_by": ("option", "uncertainty", "model_file")[int(mode[1])],
                  "uncorrected_rms_deg": mode[2], "correction_error_rms_deg": mode[3]}
        return Compensation(corrected, codes[0] if single else codes, u, orient)
    if return_status:
        return corrected, (codes[0] if single else codes)
    return corrected


def _flag_targets(codes, u95, max_unc_mm, u95_policy, on_fail):
    """The CLI's per-target warnings (rch_comp.c) as RcalWarning, or the
    first as RcalError (on_fail="raise")."""
    msgs = []
    for i, c in enumerate(codes):
        if c == 2:
            msgs.append("target %d: not compensated (the solver did not converge or hit a limit); returned the closest "
                        "point found (on a path: the target plus the last good correction)" % i)
        elif c == 3:
            msgs.append("target %d: left uncompensated: the model's 95 %% position uncertainty here is above the "
                        "limit (or unknown: a model without an uncertainty meets no limit)" % i)
        elif u95_policy == "warn" and max_unc_mm and not u95[i] <= max_unc_mm:
            msgs.append("target %d: compensated, but the model's 95 %% position uncertainty at the compensated point "
                        "is %s here, above %.4f mm" % (i, "%.4f mm" % u95[i] if math.isfinite(u95[i]) else
                                                       "unknown (the model carries no uncertainty)", max_unc_mm))
    if not msgs or on_fail == "ignore":
        return
    if on_fail == "raise" and any(c in (2, 3) for c in codes):
        raise RcalError(-3, msgs[0] + ("" if len(msgs) == 1 else " (and %d more)" % (len(msgs) - 1)))
    for m in msgs:
        warnings.warn("rcal.compensate: " + m, RcalWarning, stacklevel=3)


_FORMATS = {"urdf": 0, "dh-csv": 1}


def export(model: Union["Model", "Result", PathLike], out_path: PathLike, format: str = "urdf",
           nominal_urdf: Optional[PathLike] = None, drop_joint_effects: bool = False) -> Dict[str, int]:
    """The model as a URDF or its DH table as CSV, as `rcal export --model M
    --format F --out PATH` writes it (whole or not at all, never over an
    input). model: a model file, a Model loaded from one, or a Result (its
    model file is written to a temporary directory first); format "urdf" or
    "dh-csv"; nominal_urdf: take the names from this URDF; drop_joint_effects:
    --drop-joint-effects. Returns {"written": joints or rows,
    "effects_not_carried": n}."""
    if format not in _FORMATS:
        raise ValueError("export: format must be 'urdf' or 'dh-csv'")
    tmp = None
    try:
        if isinstance(model, Result):
            tmp = tempfile.mkdtemp(prefix="rcal-export-")
            path = os.path.join(tmp, "model.json")
            model.write(path)
        elif isinstance(model, Model):
            if model.path is None:
                raise ValueError("export: this Model has no file; pass the model file or the Result")
            path = model.path
        else:
            path = model
        written, left = ctypes.c_uint(), ctypes.c_uint()
        err = ctypes.create_string_buffer(_ERR_LEN)
        _check(_lib.lib().rch_ffi_export(_path(path), _path(out_path), _FORMATS[format], _opt_path(nominal_urdf),
                                         1 if drop_joint_effects else 0, ctypes.byref(written), ctypes.byref(left),
                                         err, _ERR_LEN), err)
        return {"written": written.value, "effects_not_carried": left.value}
    finally:
        if tmp:
            shutil.rmtree(tmp, ignore_errors=True)


def report(result: "Result", directory: PathLike, diagnosis: Optional["Diagnosis"] = None, name: str = "report",
           model: Optional[PathLike] = None, tolerance_mm: Optional[float] = None) -> List[str]:
    """The HTML report of a calibration (and a diagnosis) into directory
    (created when missing), as `rcal calibrate --report` makes it:
    <name>.html with its plot data (<name>_*.csv), the calibration's JSON
    (<name>.calibration.json) and the diagnosis's (<name>.diagnosis.json)
    beside it. model: the model file of the run; None writes the result's
    model as <name>.model.json into the directory (when it is finite) and
    uses that. tolerance_mm: the verdict on the first screen passes or fails
    against it (rcal report --tolerance-mm). Returns the paths written."""
    if not isinstance(result, Result):
        raise ValueError("report: result must be an rcal.Result")
    os.makedirs(directory, exist_ok=True)
    html = os.path.join(os.fspath(directory), name + ".html")
    written = []
    if model is None and result.figure("n_data") is not None and all(
            math.isfinite(p.value) for p in result.params):
        model = os.path.join(os.fspath(directory), name + ".model.json")
        result.write(model)
        written.append(model)
    paths = ctypes.create_string_buffer(16384)
    err = ctypes.create_string_buffer(_ERR_LEN)
    _check(_lib.lib().rch_ffi_report(result._h, diagnosis._h if diagnosis is not None else None, _path(html),
                                     _opt_path(model), float(tolerance_mm) if tolerance_mm else 0.0, paths, 16384,
                                     err, _ERR_LEN), err)
    return [p for p in paths.value.decode().split("\n") if p] + written
